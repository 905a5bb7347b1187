"""Whole-body motions from contact plans, executed by Talos in MuJoCo physics (host code)."""
