"""Collisions and terrain clearance of any configuration of Talos (coal, host-only).

A contact plan's key postures pass the verifier's collision check (`contacts.verify`, check
3): every collision mesh of Talos against the terrain, the feet's raised by FOOT_CLEARANCE
along the sole normal, and the legs against the rest of the body. `BodyClearance.collisions`
applies that same check to any configuration (a motion's samples, the generator's transitions
between key postures). `BodyClearance.too_close` asks more of the geometries other than the
feet: that they keep a margin from the terrain, which a tracked motion needs (MuJoCo's
tracking error is 1-1.5 cm on the CoM; a stance knee that the planned motion brings within 2 mm of a stair's nosing touches it in simulation).
"""

from __future__ import annotations

import numpy as np


class BodyClearance:
    """Talos's collision meshes against one terrain and against themselves.

    Args:
        talos: `load_talos()`.
        terrain: a leas_jax.terrain.Terrain (boxes and meshes).
    """

    def __init__(self, talos, terrain):
        from leas_jax.contacts.robot.collision import robot_collision, terrain_collision

        self.talos = talos
        self.terrain = terrain
        self.robot = robot_collision(talos)
        self.objects = terrain_collision(terrain)
        # [G] geometries held to the margin: all but the two foot meshes, which rest on the terrain
        self._spaced = ~np.isin(np.arange(len(self.robot.names)), talos.foot_geom_ids)

    def _placements(self, q: np.ndarray):
        rot, pos = self.robot.placements_pinocchio(self.talos, q)
        return rot, pos, self.robot.world_aabb(rot, pos)

    def _object_name(self, index: int) -> str:
        from leas_jax.contacts.robot.collision import terrain_object_name

        return terrain_object_name(self.terrain, index)

    def _pair(self, g: int, b: int, rot: np.ndarray, pos: np.ndarray) -> tuple:
        """coal's arguments of geometry g at its placement (rot [G, 3, 3], pos [G, 3]) and terrain object b."""
        import coal

        return (
            self.robot.geometries[g],
            coal.Transform3s(rot[g], pos[g]),
            self.objects.shapes[b],
            self.objects.transforms[b],
        )

    def collisions(self, q: np.ndarray) -> str | None:
        """What collides in configuration q [39] (the verifier's check), or None."""
        rot, pos, aabb = self._placements(q)
        for g, b in self.robot.terrain_contacts(rot, pos, self.objects, aabb=aabb):
            return f"{self.robot.names[g]} collides with {self._object_name(b)}"
        for ga, gb in self.robot.self_contacts(rot, pos, aabb=aabb):
            return f"{self.robot.names[ga]} collides with {self.robot.names[gb]}"
        return None

    def _near_pairs(self, aabb: np.ndarray, reach: np.ndarray):
        """(geometry g, terrain object b) pairs whose bounds, g's grown by reach [G] (m; NaN:
        g left out), meet."""
        kept = ~np.isnan(reach)
        grown = aabb + np.array([-1.0, 1.0])[None, :, None] * np.where(kept, reach, 0.0)[:, None, None]
        if not len(self.objects.aabb) or not kept.any():
            return
        near = self.objects.boxes_near(
            grown[kept, 0].min(axis=0).tolist(), grown[kept, 1].max(axis=0).tolist()
        )
        lo, hi = self.objects.aabb[near, 0], self.objects.aabb[near, 1]
        overlap = np.all((grown[:, None, 0] <= hi[None]) & (grown[:, None, 1] >= lo[None]), axis=2)
        for g, k in zip(*np.nonzero(overlap & kept[:, None])):
            yield int(g), int(near[k])

    def distance(self, q: np.ndarray, reach: float) -> float:
        """Least distance, m, from a geometry other than the feet to the terrain in q [39]; `reach`
        where none is closer than that (0 or less: a collision)."""
        import coal

        rot, pos, aabb = self._placements(q)
        request, result = coal.DistanceRequest(), coal.DistanceResult()
        least = reach
        for g, b in self._near_pairs(aabb, np.where(self._spaced, reach, np.nan)):
            result.clear()
            least = min(least, coal.distance(*self._pair(g, b, rot, pos), request, result))
        return least

    def too_close(self, q: np.ndarray, margin: float) -> str | None:
        """What keeps q [39] from being taken: a geometry other than the feet within `margin`, m,
        of the terrain, a foot in it, or the legs against the body (`collisions`); None: nothing."""
        import coal

        rot, pos, aabb = self._placements(q)
        reach = np.where(self._spaced, margin, 0.0)  # [G]
        request, result = coal.CollisionRequest(), coal.CollisionResult()
        for g, b in self._near_pairs(aabb, reach):
            request.security_margin = float(reach[g])
            result.clear()
            if coal.collide(*self._pair(g, b, rot, pos), request, result):
                return f"{self.robot.names[g]} comes within {reach[g] * 100:.3g} cm of {self._object_name(b)}"
        for ga, gb in self.robot.self_contacts(rot, pos, aabb=aabb):
            return f"{self.robot.names[ga]} collides with {self.robot.names[gb]}"
        return None

    def first_too_close(self, configurations: np.ndarray, margin: float) -> tuple[int, str] | None:
        """(sample, `too_close`'s message) of the first of configurations [M, 39] refused, or None."""
        for i, q in enumerate(configurations):
            reason = self.too_close(q, margin)
            if reason:
                return i, reason
        return None
