"""Which render modes this machine offers (the drawing is elsewhere in :mod:`sgc_env.render`)."""

from __future__ import annotations

import os
import sys

__all__ = ["available_render_modes"]


def available_render_modes() -> list[str]:
    """``rgb_array`` always (TinyRenderer); ``human`` only where a GUI can open."""
    headless = sys.platform.startswith("linux") and not os.environ.get("DISPLAY")
    return ["rgb_array"] if headless else ["human", "rgb_array"]
