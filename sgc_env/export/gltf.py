"""The motion of an episode as glTF 2.0 binary (``.glb``), for Blender, game engines and the web.

What a file holds (real units: metres and seconds):

- one node per body with its mesh (sphere, rod as a cylinder, as PyBullet has them) and its
  colour; per :class:`Motion` a group node named by its label holds its bodies and the props
  that move in it (the red balls), and one animation of that label keyframes them: translation
  and rotation of every body, translation of every moving prop, at the control rate;
- the props that stay put (the target board, with the paper's bullseye rings), once;
- the goal nails as small spheres in their body's colour, named ``nail.<body>.<goal>``, the
  goal's time in the node's ``extras``;
- a root node ``z-up to y-up`` that turns PyBullet's z-up world into glTF's y-up one (a
  rotation of -90 degrees about x: ``(x, y, z)`` becomes ``(x, z, -y)``). Everything under it
  is in PyBullet's own coordinates, so a body's keyframes are the env's numbers. Blender's
  importer turns y-up back into z-up: there, world coordinates are the env's.

glTF stores keyframes as float32: positions keep about 7 significant digits (under 1e-6 m
within 16 m of the origin). Colours are the renderer's (sRGB), converted to the linear
``baseColorFactor`` glTF specifies.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sgc_env.export.meshes import Mesh, box_mesh, cylinder_mesh, sphere_mesh
from sgc_env.render.world import RING_THICKNESS, RING_TURN, bullseye_rings

if TYPE_CHECKING:
    from sgc_env.scenario import Scenario

__all__ = [
    "MAX_GLB_BYTES", "NAIL_RADIUS", "Motion", "Nail", "UP_ROTATION", "glb_bytes", "motion_of",
    "VIEWER_PAGE", "scenario_nails", "write_glb", "write_viewer",
]  # fmt: skip

MAX_GLB_BYTES = 256 << 20
"""Largest file the writer makes (checked before any work): an hour of three rods at 60 Hz
is about 25 MB; more means a runaway episode, not an animation."""
NAIL_RADIUS = 0.03
"""Radius (m) of a goal nail's marker sphere."""
UP_ROTATION = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))
"""The root node's rotation (x, y, z, w): PyBullet's z-up world to glTF's y-up one."""
_FLOAT, _UINT16, _UINT32 = 5126, 5123, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963


@dataclass(frozen=True)
class Nail:
    """A goal's world point: which body, which of its goals, when."""

    body: int
    goal: int
    time: float
    position: tuple[float, float, float]


@dataclass(frozen=True)
class Motion:
    """One flight of a scenario's bodies, sampled at its ticks.

    ``times`` (T,) strictly increasing seconds; ``positions`` (T, B, 3) body origins (the
    centre of mass, as PyBullet reports it); ``orientations`` (T, B, 4) quaternions x, y, z, w;
    ``prop_positions`` (T, P, 3): where each prop was drawn (None: each prop's own path,
    ``Prop.position_at``). ``label`` names the group node and the animation.
    """

    label: str
    times: np.ndarray
    positions: np.ndarray
    orientations: np.ndarray
    prop_positions: np.ndarray | None = None

    def checked(self, bodies: int, props: int) -> Motion:
        """This motion as float64 arrays of the scene's shape; a ValueError naming the field
        that does not fit (wrong shape, not finite, times not increasing)."""
        times = np.asarray(self.times, float)
        t = len(times)
        fields = {"positions": (self.positions, (t, bodies, 3)),
                  "orientations": (self.orientations, (t, bodies, 4))}  # fmt: skip
        if self.prop_positions is not None:
            fields["prop_positions"] = (self.prop_positions, (t, props, 3))
        if not self.label or not isinstance(self.label, str):
            raise ValueError(f"motion label: expected a non-empty name, got {self.label!r}")
        if times.ndim != 1 or t < 1 or not np.isfinite(times).all():
            raise ValueError(f"motion {self.label!r}: times: expected (T,) finite seconds")
        if t > 1 and not (np.diff(times.astype(np.float32)) > 0).all():
            raise ValueError(f"motion {self.label!r}: times: must increase (as float32)")
        arrays = {}
        for name, (value, shape) in fields.items():
            array = np.asarray(value, float)
            if array.shape != shape:
                raise ValueError(f"motion {self.label!r}: {name}: expected shape {shape}, "
                                 f"got {array.shape}")  # fmt: skip
            if not np.isfinite(array).all():
                raise ValueError(f"motion {self.label!r}: {name}: not finite")
            arrays[name] = array
        norms = np.linalg.norm(arrays["orientations"], axis=-1, keepdims=True)
        if not (norms > 1e-9).all():
            raise ValueError(f"motion {self.label!r}: orientations: a zero quaternion")
        return Motion(self.label, times, arrays["positions"], arrays["orientations"] / norms,
                      arrays.get("prop_positions"))  # fmt: skip


def motion_of(label: str, infos: Sequence[Mapping[str, Any]],
              prop_positions: np.ndarray | None = None) -> Motion:  # fmt: skip
    """The motion an episode's infos record: ``infos`` is the reset's info, then every step's
    (each with ``time``, ``body_position`` and ``body_orientation``, as every SGC env gives)."""
    if not infos:
        raise ValueError("motion: expected the reset's info and the steps' infos, got none")
    try:
        times = np.array([float(info["time"]) for info in infos])
        positions = np.array([np.asarray(info["body_position"], float) for info in infos])
        orientations = np.array([np.asarray(info["body_orientation"], float) for info in infos])
    except KeyError as exc:
        raise ValueError(f"motion: an info without {exc}: not an SGC env's info") from None
    return Motion(label, times, positions, orientations, prop_positions)


def scenario_nails(scenario: Scenario) -> list[Nail]:
    """Every goal nail of a resolved scenario (a prop-bound nail where the prop is at the
    goal's time), in body and goal order."""
    from sgc_env.metrics.scenario_goals import goals_from_scenario

    return [Nail(b, g, spec.time, spec.nail)
            for b, specs in enumerate(goals_from_scenario(scenario))
            for g, spec in enumerate(specs) if spec.nail is not None]  # fmt: skip


def estimated_bytes(motions: Sequence[Motion], bodies: int, props: int) -> int:
    """An upper bound of the keyframes' bytes (meshes add a few hundred kB at most)."""
    per_tick = 4 + bodies * 28 + props * 12
    return sum(len(np.asarray(m.times)) * per_tick for m in motions) + (1 << 20)


def glb_bytes(scenario: Scenario, motions: Sequence[Motion],
              rod_radius: float | None = None) -> bytes:  # fmt: skip
    """The scene of a resolved ``scenario`` (its nails included) with each motion as a named
    animation, as GLB bytes.

    ``rod_radius``: draw rods this thick (at least their physical radius), as the demo's video
    does; the keyframes do not change."""
    if not motions:
        raise ValueError("glTF: expected at least one motion")
    labels = [m.label for m in motions]
    if len(set(labels)) != len(labels):
        raise ValueError(f"glTF: motion labels must differ, got {labels}")
    bodies, props = len(scenario.bodies), len(scenario.props)
    size = estimated_bytes(motions, bodies, props)
    if size > MAX_GLB_BYTES:
        raise ValueError(f"glTF: the motion needs about {size >> 20} MiB, over the "
                         f"{MAX_GLB_BYTES >> 20} MiB cap of a file")  # fmt: skip
    if rod_radius is not None and not (math.isfinite(rod_radius) and rod_radius > 0):
        raise ValueError(f"rod_radius: expected a positive number of metres, got {rod_radius!r}")
    checked = [m.checked(bodies, props) for m in motions]
    return _Builder(scenario, rod_radius).build(checked, scenario_nails(scenario))


def write_glb(path: str | Path, scenario: Scenario, motions: Sequence[Motion],
              rod_radius: float | None = None) -> Path:  # fmt: skip
    """Write :func:`glb_bytes` to ``path``; ``path``."""
    data = glb_bytes(scenario, motions, rod_radius)
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_bytes(data)
    return target


VIEWER_PAGE = "viewer.html"
"""The three.js page (package data) that shows a file in a browser; its comment says how."""


def write_viewer(folder: str | Path, file: str = "three_rods.glb") -> Path:
    """Copy :data:`VIEWER_PAGE` into ``folder``, showing ``file`` (a name in that folder)
    unless the address asks for another; its path."""
    from importlib.resources import files

    if Path(file).name != file or not file.endswith(".glb") or '"' in file:
        raise ValueError(f"viewer: expected a .glb file name beside the page, got {file!r}")
    page = files("sgc_env.export").joinpath(VIEWER_PAGE).read_text("utf-8")
    target = Path(folder) / VIEWER_PAGE
    target.write_text(page.replace('"three_rods.glb";', f'"{file}";'), "utf-8")
    return target


def linear_color(rgba: Sequence[float]) -> list[float]:
    """An sRGB colour (what the renderer paints) as glTF's linear ``baseColorFactor``."""
    rgb = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgba[:3]]
    alpha = float(rgba[3]) if len(rgba) > 3 else 1.0
    return [float(c) for c in rgb] + [alpha]


def _hemisphere_continuous(quaternions: np.ndarray) -> np.ndarray:
    """``quaternions`` (T, B, 4) with signs flipped so that consecutive keys lie in the same
    hemisphere: a viewer's slerp between two keys then takes the short way, as the body did."""
    out = quaternions.copy()
    for t in range(1, len(out)):
        flip = np.sum(out[t] * out[t - 1], axis=-1) < 0.0
        out[t, flip] *= -1.0
    return out


class _Builder:
    """Assembles one GLB: a binary blob of aligned views, and the JSON that points into it."""

    def __init__(self, scenario: Scenario, rod_radius: float | None) -> None:
        import pygltflib

        self.gl = pygltflib
        self.scenario = scenario
        self.rod_radius = rod_radius
        self.blob = bytearray()
        self.doc = pygltflib.GLTF2(
            asset=pygltflib.Asset(version="2.0", generator="sgc (sgc_env.export.gltf)"),
            scene=0,
        )
        self.meshes: dict[tuple[Any, ...], int] = {}
        self.materials: dict[tuple[float, ...], int] = {}

    def build(self, motions: Sequence[Motion], nails: Sequence[Nail]) -> bytes:
        gl, doc = self.gl, self.doc
        root = self._node(gl.Node(name="z-up to y-up", rotation=list(UP_ROTATION)))
        motions = [self._with_prop_path(m) for m in motions]  # each prop path drawn once
        moving = self._moving_props(motions)
        children = [self._motion(motion, moving) for motion in motions]
        still = [k for k in range(len(self.scenario.props)) if k not in moving]
        if still:
            children.append(self._node(gl.Node(
                name="props", children=[self._prop(k, motions[0], 0) for k in still])))
        if nails:
            children.append(self._node(gl.Node(
                name="nails", children=[self._nail(n) for n in nails])))
        doc.nodes[root].children = children
        doc.scenes = [gl.Scene(name=self.scenario.name or "sgc", nodes=[root])]
        doc.extras = {"units": "metres, seconds", "up": "z (PyBullet) under a y-up root node"}
        doc.buffers = [gl.Buffer(byteLength=len(self.blob))]
        doc.set_binary_blob(bytes(self.blob))
        return b"".join(doc.save_to_bytes())

    def _moving_props(self, motions: Sequence[Motion]) -> set[int]:
        """Props whose drawn position changes in any motion: keyframed inside each group."""
        moving = set()
        for motion in motions:
            path = motion.prop_positions
            assert path is not None
            moving |= {k for k in range(path.shape[1]) if np.ptp(path[:, k], axis=0).any()}
        return moving

    def _with_prop_path(self, motion: Motion) -> Motion:
        """``motion`` with its props' positions: as given, else each prop's own path."""
        if motion.prop_positions is not None:
            return motion
        path = np.asarray([[p.position_at(float(t)) for p in self.scenario.props]
                           for t in motion.times], float).reshape(len(motion.times), -1, 3)
        return dataclasses.replace(motion, prop_positions=path)

    def _motion(self, motion: Motion, moving: set[int]) -> int:
        gl = self.gl
        orientations = _hemisphere_continuous(motion.orientations)
        samplers: list[Any] = []
        channels: list[Any] = []
        times = self._accessor(motion.times.astype(np.float32), "SCALAR", minmax=True)

        def keyframe(node: int, path: str, values: np.ndarray) -> None:
            kind = "VEC4" if path == "rotation" else "VEC3"
            output = self._accessor(values.astype(np.float32), kind)
            samplers.append(gl.AnimationSampler(input=times, output=output,
                                                interpolation="LINEAR"))  # fmt: skip
            channels.append(gl.AnimationChannel(
                sampler=len(samplers) - 1, target=gl.AnimationChannelTarget(node=node, path=path)))

        members = []
        for b, body in enumerate(self.scenario.bodies):
            node = self._node(gl.Node(
                name=f"{motion.label}/{body.name}", mesh=self._body_mesh(body),
                translation=[float(x) for x in motion.positions[0, b]],
                rotation=[float(x) for x in orientations[0, b]],
            ))  # fmt: skip
            keyframe(node, "translation", motion.positions[:, b])
            keyframe(node, "rotation", orientations[:, b])
            members.append(node)
        path = motion.prop_positions
        assert path is not None
        for k in sorted(moving):
            node = self._prop(k, motion, 0, prefix=f"{motion.label}/")
            keyframe(node, "translation", path[:, k])
            members.append(node)
        self.doc.animations.append(gl.Animation(name=motion.label, samplers=samplers,
                                                channels=channels))  # fmt: skip
        return self._node(gl.Node(name=motion.label, children=members))

    def _prop(self, k: int, motion: Motion, tick: int, prefix: str = "") -> int:
        gl = self.gl
        prop = self.scenario.props[k]
        children = self._bullseye(prop.size) if prop.name == "target" and prop.shape == "box" \
            else []  # fmt: skip
        mesh = self._mesh(prop.shape, tuple(float(s) for s in prop.size), prop.color)
        return self._node(gl.Node(
            name=f"{prefix}{prop.name}", mesh=mesh, children=children,
            translation=[float(x) for x in np.asarray(motion.prop_positions)[tick, k]],
        ))  # fmt: skip

    def _bullseye(self, half: Sequence[float]) -> list[int]:
        """The paper's rings on the board's -x face (as the renderer draws them)."""
        out = []
        for k, ring in enumerate(bullseye_rings(half)):
            mesh = self._mesh("rod", (RING_THICKNESS, ring.radius), ring.color)
            out.append(self._node(self.gl.Node(
                name=f"ring {k}", mesh=mesh, translation=[ring.offset, 0.0, 0.0],
                rotation=list(RING_TURN),
            )))  # fmt: skip
        return out

    def _nail(self, nail: Nail) -> int:
        body = self.scenario.bodies[nail.body]
        mesh = self._mesh("sphere", (NAIL_RADIUS,), body.color)
        return self._node(self.gl.Node(
            name=f"nail.{body.name}.{nail.goal}", mesh=mesh,
            translation=[float(x) for x in nail.position],
            extras={"body": body.name, "goal": nail.goal, "time": nail.time},
        ))  # fmt: skip

    def _body_mesh(self, body: Any) -> int:
        size = tuple(float(s) for s in body.size)
        if body.shape == "rod" and self.rod_radius is not None:
            size = (size[0], max(size[1], self.rod_radius))
        return self._mesh(body.shape, size, body.color)

    def _mesh(self, shape: str, size: tuple[float, ...], color: Sequence[float]) -> int:
        key = (shape, size, tuple(color))
        if key in self.meshes:
            return self.meshes[key]
        gl = self.gl
        positions, normals, indices = _shape_mesh(shape, size)
        attributes = gl.Attributes(
            POSITION=self._accessor(positions.astype(np.float32), "VEC3", minmax=True,
                                    target=_ARRAY_BUFFER),
            NORMAL=self._accessor(normals.astype(np.float32), "VEC3", target=_ARRAY_BUFFER),
        )  # fmt: skip
        small = indices.max() < 65536
        index = self._accessor(indices.astype(np.uint16 if small else np.uint32), "SCALAR",
                               target=_ELEMENT_ARRAY_BUFFER)  # fmt: skip
        primitive = gl.Primitive(attributes=attributes, indices=index,
                                 material=self._material(color))  # fmt: skip
        self.doc.meshes.append(gl.Mesh(name=f"{shape} {size}", primitives=[primitive]))
        self.meshes[key] = len(self.doc.meshes) - 1
        return self.meshes[key]

    def _material(self, color: Sequence[float]) -> int:
        factor = tuple(linear_color(color))
        if factor not in self.materials:
            gl = self.gl
            self.doc.materials.append(gl.Material(
                pbrMetallicRoughness=gl.PbrMetallicRoughness(
                    baseColorFactor=list(factor), metallicFactor=0.0, roughnessFactor=0.6),
                alphaMode="BLEND" if factor[3] < 1.0 else "OPAQUE",
            ))  # fmt: skip
            self.materials[factor] = len(self.doc.materials) - 1
        return self.materials[factor]

    def _node(self, node: Any) -> int:
        self.doc.nodes.append(node)
        return len(self.doc.nodes) - 1

    def _accessor(self, data: np.ndarray, kind: str, minmax: bool = False,
                  target: int | None = None) -> int:  # fmt: skip
        """``data`` appended to the blob (4-byte aligned) behind a view and an accessor."""
        gl = self.gl
        while len(self.blob) % 4:
            self.blob.append(0)
        raw = np.ascontiguousarray(data).tobytes()
        self.doc.bufferViews.append(gl.BufferView(buffer=0, byteOffset=len(self.blob),
                                                  byteLength=len(raw), target=target))  # fmt: skip
        self.blob.extend(raw)
        component = {np.dtype(np.float32): _FLOAT, np.dtype(np.uint16): _UINT16,
                     np.dtype(np.uint32): _UINT32}[data.dtype]  # fmt: skip
        rows = data.reshape(len(data), -1)
        accessor = gl.Accessor(bufferView=len(self.doc.bufferViews) - 1, componentType=component,
                               count=len(data), type=kind)  # fmt: skip
        if minmax:
            accessor.min = [float(x) for x in rows.min(axis=0)]
            accessor.max = [float(x) for x in rows.max(axis=0)]
        self.doc.accessors.append(accessor)
        return len(self.doc.accessors) - 1


def _shape_mesh(shape: str, size: tuple[float, ...]) -> Mesh:
    if shape == "sphere":
        return sphere_mesh(size[0])
    if shape == "rod":
        return cylinder_mesh(size[1], size[0])
    if shape == "box":
        return box_mesh(size)
    raise ValueError(f"glTF: unknown shape {shape!r}")
