"""Support surfaces: coplanar touching faces form one surface; a sole may rest across them, not across a gap."""

import numpy as np

from leas_jax.contacts.planner.projection import rotz as _rotz
from leas_jax.contacts.planner.surfaces import find_support, sole_inside_union, surface_arrays
from leas_jax.terrain import loads_terrain

HEAD = 'name = "s"\nbounds = [[-2.0, -2.0], [4.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
TOL = 0.005  # m, docs/design.md §6 check 1


def box(center, size):
    return f"[[box]]\ncenter = {list(map(float, center))}\nsize = {list(map(float, size))}\n"


# Tops at z = 0: A x in [-1, 0] and B x in [0, 1] meet at x = 0; C x in [1.03, 2] is 3 cm
# beyond B (a gap); D x in [-1, 1], y in [1.2, 1.8] touches nothing; E, 0.1 m higher, touches B.
TERRAIN = loads_terrain(
    HEAD
    + box([-0.5, 0, -0.1], [1, 1, 0.2])
    + box([0.5, 0, -0.1], [1, 1, 0.2])
    + box([1.515, 0, -0.1], [0.97, 1, 0.2])
    + box([0, 1.5, -0.1], [2, 0.6, 0.2])
    + box([0.5, -0.75, -0.05], [1, 0.5, 0.3])
)


def test_groups_join_touching_faces_of_one_plane_only():
    surfaces = surface_arrays(TERRAIN, 0.5)
    group = {s.box_index: int(g) for s, g in zip(surfaces.surfaces, surfaces.group)}
    assert group[0] == group[1]  # A and B meet along x = 0
    assert len({group[0], group[2], group[3], group[4]}) == 4  # gap, apart, higher
    assert sorted(map(list, surfaces.members)) == sorted([[0, 1], [2], [3], [4]])


def _support(x, yaw=0.0):
    surfaces = surface_arrays(TERRAIN, 0.5)
    return find_support(TERRAIN, surfaces, np.array([x, 0.0, 0.0]), _rotz(yaw), TOL, np.radians(3.0), TOL)


def test_sole_across_a_seam_is_supported_across_a_gap_is_not():
    index, reason = _support(0.0)  # half on A, half on B
    assert index in (0, 1) and reason == ""
    assert _support(0.0, yaw=0.7)[0] in (0, 1)
    assert _support(0.5)[0] == 1  # inside B alone
    index, reason = _support(1.015)  # across the 3 cm gap between B and C
    assert index == -1 and "not on a support surface" in reason


def test_union_keeps_its_margin_from_the_outer_edges_only():
    surfaces = surface_arrays(TERRAIN, 0.5)
    members = surfaces.members[int(surfaces.group[0])]
    rot = _rotz(0.0)
    # The sole's side 0.065 m from its centre: at y = 0.43 it is 5 mm inside the edge y = 0.5.
    pos = np.array([[0.0, 0.430, 0.0], [0.0, 0.436, 0.0], [-0.895, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert sole_inside_union(surfaces, members, pos, rot, 0.005).tolist() == [True, False, True, True]
    # A single face: the seam is an edge of each, so the same sole needs both faces.
    assert not sole_inside_union(surfaces, [0], pos[3:], rot, 0.005)[0]
