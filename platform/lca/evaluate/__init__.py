"""Evaluation layer: the paper's protocol, its metrics and statistics."""
