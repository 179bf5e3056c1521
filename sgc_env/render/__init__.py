"""The one renderer of the project: ``env.render()`` and ``sgc demo`` draw through it.

:mod:`~sgc_env.render.camera` (views, eased shots, a camera framing a box),
:mod:`~sgc_env.render.painter` (sky, floor, shadows, trails, nails around TinyRenderer),
:mod:`~sgc_env.render.world` (visual-only copies of a scene in a client of their own) and
:mod:`~sgc_env.render.scene` (what the env draws each frame) and
:mod:`~sgc_env.render.modes` (which render modes this machine offers).
"""

from sgc_env.render.camera import Shot, View, camera_at, frame_points, orbit_view
from sgc_env.render.painter import TRAIL_SECONDS, Caster, Painter, Trail
from sgc_env.render.scene import CameraSpec, SceneRenderer, scene_points
from sgc_env.render.world import RenderWorld, box_corners

__all__ = [
    "TRAIL_SECONDS", "CameraSpec", "Caster", "Painter", "RenderWorld", "SceneRenderer", "Shot",
    "Trail", "View", "box_corners", "camera_at", "frame_points", "orbit_view", "scene_points",
]
