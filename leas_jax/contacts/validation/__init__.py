"""Validating many guide paths in parallel: pool (ValidationPool, validate_paths: the
interface), runner (PathRunner: one path, in a worker), backend (the executor protocol,
the in-process backend and the job bookkeeping), process (local worker processes),
ray_backend (the same on a Ray cluster).
"""
