"""Terrains: load and validate terrain files, rasterise heightfields, support surfaces, exports.

Host code (NumPy); see docs/architecture.md for the interface and docs/design.md §4 for the format.
"""

from leas_jax.terrain.loader import load_terrain, loads_terrain
from leas_jax.terrain.model import Box, Scenario, SupportSurface, Terrain, TerrainError

__all__ = ["Box", "Scenario", "SupportSurface", "Terrain", "TerrainError", "load_terrain", "loads_terrain"]
