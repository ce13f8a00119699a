"""A reconstruct-from-rest scene with distributions, for the run-out uncertainty
tests and benchmark: examples/runout/chain_solve.json (impulse ratio 0.3,
moment restitution 0.5, so that the draws stay clear of the physics flags) run
forward to rest, then turned round."""

from __future__ import annotations

import json

from tests.helpers import EXAMPLES

CHAIN = EXAMPLES / "runout" / "chain_solve.json"


def rest_scene(wheels=None, sd_position=0.02, sd_heading=0.5, sd_friction=0.01) -> dict:
    """The rest poses of the forward run, each a normal leaf (sds in m and deg),
    and ``runout.friction`` N(0.75, sd_friction); `wheels` replaces both cars'."""
    from impactsym.runout.chain import solve_to_rest

    scene = json.loads(CHAIN.read_text())
    scene["impact"].update(impulse_ratio=0.3, moment_restitution=0.5)
    if wheels is not None:
        for v in scene["vehicles"]:
            v["wheels"] = wheels
    forward = solve_to_rest(scene)
    for key in ("restitution", "impulse_ratio", "moment_restitution"):
        scene["impact"].pop(key)
    for v, out in zip(scene["vehicles"], forward["vehicles"]):
        v.pop("velocity")
        rest = out["rest"]
        v["rest"] = {
            "position": [{"normal": [x, sd_position]} for x in rest["position"]],
            "heading": {"normal": [rest["heading"], sd_heading]},
        }
    scene["runout"]["friction"] = {"normal": [0.75, sd_friction]}
    return scene


def nominal_scene(scene: dict) -> dict:
    """A copy of `scene` with every distribution replaced by its mean (all are normal here)."""

    def walk(x):
        if isinstance(x, dict):
            return x["normal"][0] if set(x) == {"normal"} else {k: walk(v) for k, v in x.items()}
        if isinstance(x, list):
            return [walk(v) for v in x]
        return x

    return walk(scene)
