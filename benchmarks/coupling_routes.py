"""Which coupling would show the thesis's 2-DOF u1 -> pitch 0.1 Hz peak, and what it costs: each route is the
shipped twin with some coupling parameters changed, verified at the five unseen seeds, in still air and in the
closed-loop chapters' ambient gusts (:data:`trms.experiments.plants.GUST`).

Run: ``python benchmarks/coupling_routes.py`` (about a minute per route and air on 2 cores; ``--routes``, ``--air``
and ``--gust-scale`` choose). It prints, per route, every target's value at each seed (``*`` marks a miss) and the
count of seeds meeting it.
"""

from __future__ import annotations

import argparse

from trms.experiments.plants import GUST
from trms.twin import Gust, load_spec
from trms.twin.calibration import Targets, verify
from trms.twin.calibration.tradeoffs import STRONGEST_COUPLING
from trms.twin.parameters import with_parameters

#: Routes: the shipped coupling, the bounds' strongest lean and spin inertia, and the same with a stronger main
#: rotor reaction torque (u1 drives yaw harder, so its 0.1 Hz yaw mode shows more in pitch than u2's).
ROUTES = {
    "shipped": {},
    "strongest lean": dict(STRONGEST_COUPLING),
    "strongest lean, main reaction 0.2 m": {**STRONGEST_COUPLING, "main_reaction": 0.2},
    "strongest lean, main reaction 0.3 m": {**STRONGEST_COUPLING, "main_reaction": 0.3},
}


def route_table(values: dict[str, float], gust: Gust | None) -> list[str]:
    """One Markdown row per target: its values at each unseen seed and how many seeds meet it."""
    targets = Targets.thesis()
    targets.rest = None
    v = verify(with_parameters(load_spec(), values), targets, gust=gust)
    rows: dict[str, list] = {}
    for c in v.checks:  # a channel with two peak targets has one row for each
        rows.setdefault(f"{c.name} ({c.target:.3g} {c.unit})".replace(" )", ")"), []).append(c)
    return [
        f"| {name} | "
        + " | ".join(f"{c.achieved:.3g}{'' if c.met else '*'}" for c in checks)
        + f" | {sum(c.met for c in checks)}/{len(checks)} |"
        for name, checks in rows.items()
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--routes", nargs="*", default=list(ROUTES), choices=list(ROUTES))
    parser.add_argument("--air", nargs="*", default=["still", "gusts"], choices=["still", "gusts"])
    parser.add_argument("--gust-scale", type=float, default=1.0, help="gusts' level as a fraction of GUST's")
    args = parser.parse_args()
    for name in args.routes:
        for air in args.air:
            gust = Gust(GUST[0] * args.gust_scale, GUST[1]) if air == "gusts" else None
            print(f"\n### {name}, {air} air ({ROUTES[name] or 'shipped values'})\n")
            print("| target | seed 101 | 102 | 103 | 104 | 105 | met |\n|---|---|---|---|---|---|---|")
            print("\n".join(route_table(ROUTES[name], gust)))


if __name__ == "__main__":
    main()
