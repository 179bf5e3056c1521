"""Per-solve cost of the SGC course solver next to scipy.optimize.brentq on g(z).

Usage: .venv/bin/python scripts/bench_solve.py [--n 2000] [--batch 10000] [--repeat 7]

The same random problems (gamma T in [-5, 5], k log-uniform in [0.2, 5], moderate so that
the plain g(z) used by brentq does not overflow) are solved by CourseProfile.solve (scalar,
Newton on the transformed variable), solve_batch (vectorised, per element) and brentq on
g(z) = log(k S(z)) - C(z)/S(z) - gamma T with a bracket from the asymptotes. Each timing is
the minimum over the repeats (time.perf_counter); the roots are checked to agree. The last
line times what a stateless expert does per track and control step.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.optimize import brentq

from sgc_env.paper.course import CourseProfile, solve_batch
from sgc_env.paper.frames import course_end_velocity, solve_course_in_frame


def _s_c(z: float) -> tuple[float, float]:
    if z > 0.0:
        r = math.sqrt(z)
        return math.sin(r) / r, math.cos(r)
    if z < 0.0:
        r = math.sqrt(-z)
        return math.sinh(r) / r, math.cosh(r)
    return 1.0, 1.0


def _g(z: float, gt: float, k: float) -> float:
    s, c = _s_c(z)
    return math.log(k * s) - c / s - gt


def _brentq_root(gt: float, k: float) -> float:
    y = gt - math.log(k)
    hi = math.pi**2 * (1.0 - 1e-15)
    lo = -((0.5 * math.exp(-y) + 1.0) ** 2) if y < -1.0 else -1.0
    return brentq(_g, lo, hi, args=(gt, k), xtol=1e-14, rtol=4 * np.finfo(float).eps)


def _best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2000, help="scalar problems per repeat")
    parser.add_argument("--batch", type=int, default=10000, help="batch size for solve_batch")
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    rng = np.random.default_rng(args.seed)
    gt = rng.uniform(-5.0, 5.0, args.batch)
    k = np.exp(rng.uniform(math.log(0.2), math.log(5.0), args.batch))
    problems = list(zip(gt[: args.n].tolist(), k[: args.n].tolist(), strict=True))

    def run_scalar():
        for g, kk in problems:
            CourseProfile.solve(1.0, g, 1.0, kk)

    def run_brentq():
        for g, kk in problems:
            _brentq_root(g, kk)

    def run_batch():
        solve_batch(1.0, gt, 1.0, k)

    z_ours = np.array([CourseProfile.solve(1.0, g, 1.0, kk).z for g, kk in problems])
    z_ref = np.array([_brentq_root(g, kk) for g, kk in problems])
    z_batch = solve_batch(1.0, gt, 1.0, k).beta_squared[: args.n]
    worst = float(np.max(np.abs(z_ours - z_ref) / (1.0 + np.abs(z_ref))))
    worst_b = float(np.max(np.abs(z_batch - z_ref) / (1.0 + np.abs(z_ref))))

    scalar = _best(run_scalar, args.repeat) / args.n * 1e6
    ref = _best(run_brentq, args.repeat) / args.n * 1e6
    batch = _best(run_batch, args.repeat) / args.batch * 1e6
    print(f"problems: {args.n} scalar, batch of {args.batch}; min of {args.repeat} repeats")
    print(f"CourseProfile.solve : {scalar:8.3f} us/solve")
    print(f"solve_batch         : {batch:8.3f} us/element")
    print(f"brentq on g(z)      : {ref:8.3f} us/solve")
    print(f"ratio brentq/scalar : {ref / scalar:8.2f}")
    print(f"ratio brentq/batch  : {ref / batch:8.2f}")
    print(f"max |dz|/(1+|z|) vs brentq: scalar {worst:.1e}, batch {worst_b:.1e}")
    print(f"one track, one control step: {_track_step_us(args.repeat, False):8.3f} us "
          "(course_end_velocity + solve_course_in_frame + state)")
    print(f"  same, end velocity cached: {_track_step_us(args.repeat, True):8.3f} us "
          "(solve_course_in_frame + state)")


def _track_step_us(repeat: int, cached: bool, n: int = 2000) -> float:
    """What a stateless expert does per track and control step, in microseconds."""
    d = np.array([0.3, 0.2, -0.1])
    nxt = np.array([0.25, 0.3, 0.0])
    dev, vel = 0.8 * d, np.array([-0.2, -0.1, 0.05])
    v_end, info = course_end_velocity(d, nxt, 1.0, 1.2)

    def run():
        for _ in range(n):
            if cached:
                v, frame = v_end, info.frame
            else:
                v, step_info = course_end_velocity(d, nxt, 1.0, 1.2)
                frame = step_info.frame
            solve_course_in_frame(frame, dev, vel, 0.7, v).state(1.0 / 240.0)

    return _best(run, repeat) / n * 1e6


if __name__ == "__main__":
    main()
