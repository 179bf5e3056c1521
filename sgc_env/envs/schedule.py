"""The course on schedule, ``D_sched``: the one rule that the reward and the learner's view read.

A track's course runs from its start deviation ``D_i(0)`` to the goal in ``T_i`` seconds. On
schedule, the deviation at time left ``t`` is ``D_sched = D_i(0) t / T_i`` and its rate
``D'_sched = -D_i(0) / T_i``: the paper's behaviour equation in its neutral member, the course
travelled at its average speed (why that reference: :mod:`sgc_env.envs.rewards`). Past the
course's end (``t < 0``, after the last goal) the body carries on at the goal's end velocity:
``D_sched = -v_end t`` and ``D'_sched = v_end``. A track with no course (duration 0) is past
its end. The reward charges ``|D - D_sched|``; the view hands the learner ``D - D_sched``,
``D' - D'_sched`` and ``D'_sched``.

Written once for one env (floats) and for the batch (arrays, :mod:`sgc_env.paper.elementwise`):
a vector is its components, floats or arrays, or one array whose last axis holds them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from sgc_env.paper.elementwise import all_, any_, where

__all__ = ["on_schedule"]


def on_schedule(
    start: Sequence[Any], span: Any, end_velocity: Sequence[Any], left: Any
) -> tuple[list[Any], list[Any], Any, Any]:
    """``D_sched`` and ``D'_sched`` (the module docstring) of a course with start deviation
    ``start`` and duration ``span`` at time left ``left``, then whether the course still runs
    and its time fraction ``left / T_i`` (``left`` where there is no course)."""
    if left.__class__ is float:  # one env: Python's branches on floats, the same operations
        x, y, z = start
        if left >= 0.0 and span > 0.0:
            fraction = left / span
            return (
                [x * fraction, y * fraction, z * fraction],
                [-x / span, -y / span, -z / span],
                True,
                fraction,
            )
        fraction = left / span if span > 0.0 else left
        ex, ey, ez = end_velocity
        return [-ex * left, -ey * left, -ez * left], [ex, ey, ez], False, fraction
    running = (left >= 0.0) & (span > 0.0)
    safe = where(span > 0.0, span, 1.0)
    fraction = left / safe
    if running is True or running is not False and all_(running):  # inline: a call costs more
        return [x * fraction for x in start], [-x / safe for x in start], running, fraction
    if not any_(running):
        return [-x * left for x in end_velocity], list(end_velocity), running, fraction
    deviation = [
        where(running, x * fraction, -v * left) for x, v in zip(start, end_velocity, strict=True)
    ]
    rate = [where(running, -x / safe, v) for x, v in zip(start, end_velocity, strict=True)]
    return deviation, rate, running, fraction
