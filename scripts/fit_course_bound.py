"""Measure the factors of the three-rod family's planner-free demand bound.

For ``--rods`` draws of each rod (before the feasibility check), the planner's bounds
(``demand_bounds``) against the course features (``sgc_env.scenes.course_bound``): per rod the
largest ``K_F = (force / m - |g|) / (point + r spin)`` and ``K_S = torque / (I_max spin)``, which
go into ``MEASURED_FACTORS`` of ``sgc_env/scenes/three_rods_random.py``; how many draws have no
features (a pace jump) and how many the bound with the shipped factors accepts.

    .venv/bin/python scripts/fit_course_bound.py [--rods 200] [--seed 100]
"""

from __future__ import annotations

import argparse

import numpy as np

from sgc_env.scenario.demand import demand_bounds, inertia_diagonal
from sgc_env.scenes import three_rods_random as family
from sgc_env.scenes.course_bound import course_features
from sgc_env.scenes.three_rods import ROD_SPECS


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rods", type=int, default=200, help="draws per rod")
    parser.add_argument("--seed", type=int, default=100)
    args = parser.parse_args()
    cfg = family.RandomThreeRodsConfig()
    rng = np.random.default_rng(args.seed)
    print(f"{'rod':12s} {'draws':>6s} {'K_F':>7s} {'K_S':>7s} {'no features':>12s} {'accepted':>9s}"
          f" {'planner ok':>11s}")  # fmt: skip
    for k, spec in enumerate(ROD_SPECS):
        k_force = k_spin = 0.0
        draws = none = accepted = feasible = 0
        while draws < args.rods:
            scenario = family.draw_rod(rng, k, cfg)
            if scenario is None:
                continue
            draws += 1
            body = scenario.bodies[0]
            ((force, torque),) = demand_bounds(scenario)
            share = cfg.demand_share
            feasible += force <= share * body.force_limit and torque <= share * body.torque_limit
            features = course_features(body, cfg.control_frequency)
            if features is None:
                none += 1
                continue
            point, spin = features
            arm = float(np.linalg.norm(body.goals[0].point))
            inertia = float(inertia_diagonal(body.shape, body.size, body.mass).max())
            k_force = max(k_force, (force / body.mass - 9.81) / (point + arm * spin))
            k_spin = max(k_spin, torque / (inertia * spin))
            bound = family.rod_bound(scenario, k)
            assert bound is not None
            accepted += (
                bound[0] <= share * body.force_limit and bound[1] <= share * body.torque_limit
            )
        print(f"{spec.name:12s} {draws:6d} {k_force:7.3f} {k_spin:7.3f} {none / draws:12.3f}"
              f" {accepted / draws:9.3f} {feasible / draws:11.3f}")  # fmt: skip


if __name__ == "__main__":
    main()
