"""What each command computes for the uncertainty engine: kernel columns → its JSON numbers.

A `Command` runs the batch kernels over columns (`run`), names the exact
Jacobian kernel for one scene (`jacobian_kernel`) or chains several
(`gradients`, CRASH3), and maps kernel outputs to the numbers of the
command's JSON object (`outputs`), written so that complex numbers pass (the
complex step of the linear method goes through them). Integer codes (flags,
pdof_clock) are not outputs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from .. import _kernels
from ..batch import solve_batch
from ..inverse import invert_batch
from ..laws.dispatch import is_law_model, law_kernel
from ..reconstruct import reconstruct_batch

__all__ = ["Command", "RECONSTRUCT", "command_for", "COMMANDS", "COMPLEX_STEP"]

COMMANDS = ("solve", "invert", "reconstruct", "crash3")
COMPLEX_STEP = 1e-30
DEGREES = 180.0 / math.pi


def _hypot(x, y):
    """|(x, y)|, valid for the complex step (np.hypot is real only)."""
    return np.sqrt(x * x + y * y)


def _clockwise_deg(rad):
    """A counter-clockwise angle [rad] as degrees clockwise in (-180, 180];
    the wrap acts on the real part only, so the complex step passes through."""
    deg = rad * (-180.0 / math.pi)
    real = (np.real(deg) + 180.0) % 360.0 - 180.0
    return real + 1j * np.imag(deg) if np.iscomplexobj(deg) else real


def _forward_outputs(c: Mapping, o: Mapping, yaw: bool) -> dict:
    out = {}
    for i in (1, 2):
        v = f"vehicles[{i - 1}]"
        out[f"{v}.velocity[0]"], out[f"{v}.velocity[1]"] = o[f"V{i}x"], o[f"V{i}y"]
        if yaw:
            out[f"{v}.yaw_rate"] = o[f"W{i}"]
        out[f"{v}.delta_v[0]"] = o[f"V{i}x"] - c[f"v{i}x"]
        out[f"{v}.delta_v[1]"] = o[f"V{i}y"] - c[f"v{i}y"]
        out[f"{v}.delta_v_magnitude"] = o[f"dV{i}"]
    return {**out, **_impulse_energy(o, yaw), "impulse_ratio": o["mu"], "critical_impulse_ratio": o["mu_c"]}


def _impulse_energy(o: Mapping, yaw: bool) -> dict:
    out = {"impulse.normal": o["Pn"], "impulse.tangential": o["Pt"]}
    if yaw:
        out["impulse.moment"] = o["M"]
    out.update(
        {"energy_loss.total": o["TL"], "energy_loss.normal": o["TLn"], "energy_loss.tangential": o["TLt"]}
    )
    if yaw:
        out["energy_loss.moment"] = o["TLm"]
    return out


def _inverse_outputs(c: Mapping, o: Mapping, yaw: bool) -> dict:
    out = {}
    for i in (1, 2):
        v = f"vehicles[{i - 1}]"
        out[f"{v}.velocity[0]"], out[f"{v}.velocity[1]"] = o[f"v{i}x"], o[f"v{i}y"]
        if yaw:
            out[f"{v}.yaw_rate"] = o[f"w{i}"]
        dx, dy = c[f"V{i}x"] - o[f"v{i}x"], c[f"V{i}y"] - o[f"v{i}y"]
        out[f"{v}.delta_v[0]"], out[f"{v}.delta_v[1]"] = dx, dy
        out[f"{v}.delta_v_magnitude"] = _hypot(dx, dy)
    return {**out, **_impulse_energy(o, yaw), "impulse_ratio": c["mu"], "critical_impulse_ratio": o["mu_c"]}


def _reconstruct_outputs(c: Mapping, o: Mapping, yaw: bool = True) -> dict:
    out = {}
    for i in (1, 2):
        v = f"vehicles[{i - 1}]"
        out[f"{v}.speed"] = o[f"s{i}"]
        out[f"{v}.velocity[0]"], out[f"{v}.velocity[1]"] = o[f"v{i}x"], o[f"v{i}y"]
        dx, dy = c[f"V{i}x"] - o[f"v{i}x"], c[f"V{i}y"] - o[f"v{i}y"]
        out[f"{v}.delta_v[0]"], out[f"{v}.delta_v[1]"] = dx, dy
        out[f"{v}.delta_v_magnitude"] = _hypot(dx, dy)
        out[f"{v}.pdof_deg"] = _clockwise_deg(o[f"pdof{i}"])
    return {
        **out,
        **_impulse_energy(o, True),
        "moment_residual": o["M_residual"],
        "restitution": o["e"],
        "impulse_ratio": o["mu"],
        "moment_restitution": o["e_m"],
        "critical_impulse_ratio": o["mu_c"],
    }


@dataclass(frozen=True)
class Command:
    """How one command turns kernel columns into its JSON numbers.

    `run(columns)` → (kernel outputs, status, flags) through the batch kernels;
    `jacobian(columns)` → the exact Jacobian kernel's row at one scene (kernel
    inputs → value and derivative outputs), or None where there is none;
    `outputs(columns, kernel outputs)` → JSON path → values (complex-safe)."""

    name: str
    run: Callable
    jacobian_kernel: Callable
    outputs: Callable
    gradients: Callable | None = None


def _forward_command(model: str) -> Command:
    family, fixed = _kernels.preset(model)
    yaw = family != "particle"

    def kernel(columns):
        if family not in ("rigid", "particle"):
            return None, {}
        critical = fixed.get("mu") == "critical" or columns.get("mu") == "critical"
        extra = {k: v for k, v in fixed.items() if k != "mu"}
        return _kernels.JACOBIAN[family + ("_critical" if critical else "")], extra

    return Command(
        "solve",
        lambda c: _split(solve_batch(c, model=model)),
        kernel,
        lambda c, o: _forward_outputs(c, o, yaw),
    )


def _inverse_command(family: str) -> Command:
    yaw = family != "particle"
    return Command(
        "invert",
        lambda c: _split(invert_batch(c, model=family)),
        lambda c: (_kernels.JACOBIAN[f"{family}_inverse"], {}),
        lambda c, o: _inverse_outputs(c, o, yaw),
    )


RECONSTRUCT = Command(
    "reconstruct",
    lambda c: _split(reconstruct_batch(c)),
    lambda c: (_kernels.JACOBIAN["reconstruct"], {}),
    _reconstruct_outputs,
)


def _split(result: Mapping):
    outs = {k: v for k, v in result.items() if k not in ("status", "flags")}
    return outs, np.asarray(result["status"]), np.asarray(result["flags"])


# --------------------------------------------------------------------------- CRASH3: a chain of kernels


def _crash3_stages(c: Mapping, options, units: str, tangents: list | None = None):
    """CRASH3 over columns `c` (scene_columns' crash3 form) with `options`
    (`impactsym.crash3.Crash3Options`: restitution, energy mode, oblique
    correction): per vehicle the crush-energy kernel (its output for the
    correction: E or E_woolley), radius of gyration and moment arm, then the
    delta-V kernel of the energy mode (dissipated or absorbed) on the total
    energy. With `tangents` (per input, d column) the exact Jacobian kernels
    of each stage carry them through too (one scene). Returns (values by
    name, status, per-input tangents by name)."""
    from ..crash3.model import CORRECTED_OUTPUT, DELTA_V_KERNELS, ENERGY_FACTOR

    factor = ENERGY_FACTOR[units]
    corrected = CORRECTED_OUTPUT[options.correction]
    delta_v = DELTA_V_KERNELS[options.energy]
    n = max(
        [np.size(v) for k, v in c.items() if k != "crush"]
        + [np.size(v) for crush in c["crush"] if crush for v in crush.values()]
    )
    vals, status = {}, np.zeros(n, dtype=np.int32)
    tan = [dict(t) for t in tangents] if tangents is not None else None

    def stage(name: str, ks, inputs: dict, prefix: str = ""):
        args = [inputs[k] for k in ks.inputs]
        if tan is None:
            outs, st, _fl = _kernels.run_batch(ks, args, n)
        else:
            jk = _kernels.JACOBIAN[name]
            row = _kernels.run_one(jk, {k: float(np.ravel(v)[0]) for k, v in inputs.items()}, jk.outputs)
            st = np.array([row["status"]])
            outs = {o: np.array([row[o]]) for o in ks.outputs}
            for t in tan:
                for o in ks.outputs:
                    t[prefix + o] = sum(
                        row.get(f"d_{o}__d_{x}", 0.0) * t.get(inputs_key[x], 0.0) for x in ks.inputs
                    )
        np.copyto(status, st, where=status == 0)
        return outs

    for i, crush in enumerate(c["crush"], start=1):
        if crush is None:
            vals.update(
                {
                    f"E{i}": 0.0,
                    f"E_crush{i}": 0.0,
                    f"rg{i}": math.inf,
                    f"h{i}": 0.0,
                    f"alpha{i}": 0.0,
                    f"m{i}": math.inf,
                }
            )
            continue
        depths = sum(1 for k in crush if k.startswith("C") and k[1:].isdigit())
        inputs_key = {k: f"crush{i}.{k}" for k in crush}
        out = stage(f"crash3_energy_{depths}", _kernels.CRASH3_ENERGY[depths], crush, f"energy{i}.")
        vals[f"E_crush{i}"], vals[f"E{i}"] = out["E_crush"] * factor, out[corrected] * factor
        vals[f"alpha{i}"], vals[f"m{i}"] = crush["alpha"], c[f"m{i}"]
        if tan is not None:
            for t in tan:
                t[f"E{i}"] = t[f"energy{i}.{corrected}"] * factor
                t[f"E_crush{i}"] = t[f"energy{i}.E_crush"] * factor
                t[f"alpha{i}"], t[f"m{i}"] = t.get(f"crush{i}.alpha", 0.0), t.get(f"m{i}", 0.0)
        if "radius_of_gyration" in crush:
            vals[f"rg{i}"] = crush["radius_of_gyration"]
            _alias(tan, f"rg{i}", f"crush{i}.radius_of_gyration")
        elif np.all(np.isfinite(c[f"I{i}"])):
            inputs_key = {"mass": f"m{i}", "inertia": f"I{i}"}
            vals[f"rg{i}"] = stage(
                "crash3_radius_of_gyration",
                _kernels.CRASH3_RADIUS_OF_GYRATION,
                {"mass": c[f"m{i}"], "inertia": c[f"I{i}"]},
                f"rg{i}.",
            )["rg"]
            _alias(tan, f"rg{i}", f"rg{i}.rg")
        else:
            vals[f"rg{i}"] = math.inf
        if "moment_arm" in crush:
            vals[f"h{i}"] = crush["moment_arm"]
            _alias(tan, f"h{i}", f"crush{i}.moment_arm")
        else:
            theta = c["gamma"] + crush["alpha"]
            if tan is not None:
                for t in tan:
                    t[f"theta{i}"] = t.get("gamma", 0.0) + t.get(f"crush{i}.alpha", 0.0)
            inputs_key = {"rx": f"r{i}x", "ry": f"r{i}y", "theta": f"theta{i}"}
            vals[f"h{i}"] = stage(
                "crash3_moment_arm",
                _kernels.CRASH3_MOMENT_ARM,
                {"rx": c[f"r{i}x"], "ry": c[f"r{i}y"], "theta": theta},
                f"h{i}.",
            )["h"]
            _alias(tan, f"h{i}", f"h{i}.h")
    vals["E"] = vals["E1"] + vals["E2"]
    if tan is not None:
        for t in tan:
            t["E"] = t.get("E1", 0.0) + t.get("E2", 0.0)
    inputs_key = {k: k for k in ("m1", "m2", "rg1", "rg2", "h1", "h2", "E", "e", "gamma", "alpha1", "alpha2")}
    dv_inputs = {k: vals[k] if k in vals else c[k] for k in inputs_key if k != "e"}
    dv_inputs["e"] = options.restitution
    vals.update(stage(delta_v.name, delta_v, dv_inputs, "dv."))
    if tan is not None:
        for t in tan:
            for o in delta_v.outputs:
                t[o] = t[f"dv.{o}"]
    return vals, status, tan


def _alias(tangents, name: str, source: str) -> None:
    if tangents is not None:
        for t in tangents:
            t[name] = t.get(source, 0.0)


def _crash3_outputs(c: Mapping, v: Mapping) -> dict:
    out = {}
    for i in (1, 2):
        p = f"vehicles[{i - 1}]"
        out.update(
            {
                f"{p}.crush_energy": v[f"E{i}"],
                f"{p}.crush_energy_uncorrected": v[f"E_crush{i}"],
                f"{p}.effective_mass_factor": v[f"mass_factor{i}"],
                f"{p}.moment_arm": v[f"h{i}"],
                f"{p}.delta_v[0]": v[f"dV{i}x"],
                f"{p}.delta_v[1]": v[f"dV{i}y"],
                f"{p}.delta_v_magnitude": v[f"dV{i}"],
                f"{p}.pdof": v[f"alpha{i}"] * DEGREES,
            }
        )
        if f"dV{i}_eff" in v:  # EDCRASH's effective-mass delta-V, where the kernel has it
            out[f"{p}.delta_v_effective_mass"] = v[f"dV{i}_eff"]
    out["energy_total"], out["impulse"] = v["E"], v["P"]
    return out


def _crash3_command(units: str, options) -> Command:
    """CRASH3 with `options` (restitution, energy mode, oblique correction) as
    a chain of kernels; its gradients chain their exact Jacobians."""

    def run(c):
        vals, status, _ = _crash3_stages(c, options, units)
        return vals, status, np.zeros_like(status)

    def gradients(base: dict, dcols: list) -> dict:
        vals, status, tan = _crash3_stages(base, options, units, dcols)
        if status[0] != 0:
            return {}
        values = _crash3_outputs(base, {k: np.ravel(x)[0] if np.ndim(x) else x for k, x in vals.items()})
        grads = {path: np.zeros(len(dcols)) for path in values}
        for j, t in enumerate(tan):
            h = COMPLEX_STEP
            cplx = {
                k: complex(np.ravel(x)[0] if np.ndim(x) else x, h * t.get(k, 0.0)) for k, x in vals.items()
            }
            for path, y in _crash3_outputs(base, cplx).items():
                grads[path][j] = np.imag(y) / h
        return grads

    return Command("crash3", run, lambda c: (None, {}), _crash3_outputs, gradients)


def command_for(
    command: str,
    model: str = "rigid",
    units: str = "SI",
    restitution: float = 0.0,
    energy: str = "dissipated",
    correction: str = "crash3",
) -> Command:
    """The Command of ``solve`` (any model), ``invert`` (rigid, particle),
    ``reconstruct`` or ``crash3`` (scene units and CRASH3's options: its
    restitution, ``energy`` "dissipated" | "absorbed" and ``correction``
    "crash3" | "woolley", as `impactsym.crash3`)."""
    if command == "crash3":
        from ..crash3 import Crash3Options

        return _crash3_command(units, Crash3Options(restitution, energy, correction))
    if command == "solve" and is_law_model(model):  # impactsym.laws: the law's own Jacobian kernel
        jacobian = _kernels.JACOBIAN[law_kernel(model).name]
        return Command(
            "solve",
            lambda c: _split(solve_batch(c, model=model)),
            lambda c: (jacobian, {}),
            lambda c, o: _forward_outputs(c, o, True),
        )
    if command == "solve":
        return _forward_command(model)
    if command == "invert":
        return _inverse_command(_kernels.preset(model)[0])
    if command == "reconstruct":
        return RECONSTRUCT
    raise ValueError(f"command: unknown command {command!r} (use one of {', '.join(COMMANDS)})")
