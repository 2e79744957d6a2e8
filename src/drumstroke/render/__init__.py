"""Outputs of strokes: data files (JSON, CSV) and pictures (PNG, with the ``plot`` extra)."""
