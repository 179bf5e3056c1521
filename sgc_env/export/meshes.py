"""Triangle meshes of the scene's shapes, in the body frame PyBullet uses for them.

A sphere of radius ``r`` about the origin; a rod as a closed cylinder along the body's z axis
(PyBullet's ``GEOM_CYLINDER``, the rod's collision and render shape), centred on the origin;
a box by its half extents. Each mesh is ``(positions (n, 3), normals (n, 3), indices (m,))``
with outward unit normals and counter-clockwise faces seen from outside, as glTF expects.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["Mesh", "box_mesh", "cylinder_mesh", "sphere_mesh"]

Mesh = tuple[np.ndarray, np.ndarray, np.ndarray]
SEGMENTS = 32
"""Facets around a sphere or a cylinder: smooth at video size, a few kB a mesh."""


def sphere_mesh(radius: float, segments: int = SEGMENTS, rings: int = SEGMENTS // 2) -> Mesh:
    """A UV sphere: ``rings + 1`` latitude rows (poles included) of ``segments + 1`` vertices
    (the seam duplicated so that each row closes)."""
    theta = np.linspace(0.0, np.pi, rings + 1)[:, None]
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)[None, :]
    normals = np.stack(
        [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta) + 0.0 * phi],
        axis=-1,
    ).reshape(-1, 3)
    row = segments + 1
    faces = []
    for i in range(rings):
        for j in range(segments):
            a, b = i * row + j, (i + 1) * row + j
            if i > 0:
                faces.append((a, b, a + 1))
            if i < rings - 1:
                faces.append((a + 1, b, b + 1))
    return radius * normals, normals, np.asarray(faces, np.uint32).ravel()


def cylinder_mesh(radius: float, length: float, segments: int = SEGMENTS) -> Mesh:
    """A closed cylinder along z from ``-length / 2`` to ``+length / 2``: a side of two rings
    with radial normals, and two caps (a centre and a ring each) with normals along the axis."""
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    ring = np.stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)], axis=-1)
    half = length / 2.0
    n = segments + 1
    side = np.concatenate([radius * ring + [0, 0, -half], radius * ring + [0, 0, half]])
    positions = [side]
    normals = [np.concatenate([ring, ring])]
    faces = [(j, j + 1, n + j) for j in range(segments)]
    faces += [(j + 1, n + j + 1, n + j) for j in range(segments)]
    for sign in (-1.0, 1.0):
        start = sum(len(p) for p in positions)
        cap = np.concatenate([[[0.0, 0.0, sign * half]], radius * ring + [0, 0, sign * half]])
        positions.append(cap)
        normals.append(np.tile([0.0, 0.0, sign], (n + 1, 1)))
        for j in range(segments):
            a, b = start + 1 + j, start + 2 + j
            faces.append((start, a, b) if sign > 0 else (start, b, a))
    return (np.concatenate(positions), np.concatenate(normals),
            np.asarray(faces, np.uint32).ravel())  # fmt: skip


def box_mesh(half: Sequence[float]) -> Mesh:
    """An axis-aligned box of half extents ``half``: four vertices a face, flat normals."""
    h = np.asarray(half, float)
    positions: list[np.ndarray] = []
    normals: list[np.ndarray] = []
    faces: list[tuple[int, int, int]] = []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for sign in (-1.0, 1.0):
            normal = np.zeros(3)
            normal[axis] = sign
            corners = []
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                c = np.zeros(3)
                c[axis], c[u], c[v] = sign, du * sign, dv
                corners.append(c * h)
            start = len(positions) * 4
            positions.append(np.asarray(corners))
            normals.append(np.tile(normal, (4, 1)))
            faces += [(start, start + 1, start + 2), (start, start + 2, start + 3)]
    return (np.concatenate(positions), np.concatenate(normals),
            np.asarray(faces, np.uint32).ravel())  # fmt: skip
