"""Learned feasibility models and their data: the fitting of the env's learned condition
(`fit`; the condition itself: `leas_jax.env.learned_feasibility`), the walking truth that labels
it, the walkability model of rough ground, the generator-verified spawns and `leas feasibility`.

The package imports nothing itself, so that `leas --help` builds the `feasibility` command
without starting JAX: import from its modules (`from leas_jax.feasibility.fit import fit`).
"""
