"""Evaluation: the listening test's statistics."""
