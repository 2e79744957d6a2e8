"""Evaluation (SPEC §6): the listening test's statistics."""
