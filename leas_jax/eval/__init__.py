"""Evaluation: geometric metrics, reports (and, later, the paper's scenarios)."""
