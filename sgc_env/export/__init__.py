"""The motion out of the project, for animators' tools: glTF 2.0 binary files
(:mod:`~sgc_env.export.gltf`) of a scenario's bodies, props and nails with each flight as a
keyframed animation."""

from sgc_env.export.gltf import (
    MAX_GLB_BYTES,
    Motion,
    glb_bytes,
    motion_of,
    write_glb,
    write_viewer,
)

__all__ = ["MAX_GLB_BYTES", "Motion", "glb_bytes", "motion_of", "write_glb", "write_viewer"]
