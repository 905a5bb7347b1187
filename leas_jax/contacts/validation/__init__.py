"""Validating many guide paths in parallel: pool (local worker processes), ray_backend
(the same on a Ray cluster).
"""
