"""The case-file language: the keys a scene may use, its numeric leaves, and
the reconstructionist's alternative forms, normalised to the scene frame.

A *leaf* is one number of a scene, named by its path as written
(``vehicles[0].velocity.speed``, ``vehicles[0].final_velocity[1]``,
``impact.normal_angle``, ``vehicles[1].crush.depths[2]``). It may be

- a bare number, in the unit of the scene's ``units`` system (angles in degrees,
  yaw rates in rad/s);
- a string with a unit (``"35 mph"``, ``"3451 lb"``; :mod:`impactsym.scene.units`);
- a distribution: ``{"normal": [mean, sd]}``, ``{"uniform": [low, high]}``,
  ``{"triangular": [low, mode, high]}``, each value a number or a unit string.
  The nominal value (mean, midpoint, mode) is what the plain commands solve.

:class:`LeafReader` reads and checks leaves and keeps them, in scene units, as
:class:`Leaf` records. The alternative forms (``weight`` for ``mass``,
``radius_of_gyration`` for ``yaw_inertia``, ``{"speed", "direction"}`` for a
velocity, ``{"forward", "left"}`` or ``{"distance", "angle"}`` for an impact
point in the vehicle frame,
either sense of ``normal_angle``) are computed from the leaves by
:func:`vehicle_state` and :func:`used_normal_angle` with NumPy operations that
take floats and arrays alike: the nominal scene and a batch of uncertainty
draws go through the same code.

Conventions: directions and headings are degrees counter-clockwise from +x;
``heading`` is the direction of the vehicle's longitudinal axis (where its
front points); in the vehicle frame ``forward`` is along the heading and
``left`` 90° counter-clockwise from it; ``angle`` is counter-clockwise from
the heading (to the left). ``mass = weight / g_n`` with
g_n = 9.80665 m/s² (:data:`impactsym.scene.units.STANDARD_GRAVITY`).
"""

from __future__ import annotations

import difflib
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SceneError, show_value
from .fields import finite_float
from .units import GRAVITY, to_scene_units

__all__ = [
    "COEFFICIENT_KEYS",
    "DISTRIBUTIONS",
    "IMPACT_KEYS",
    "TOP_KEYS",
    "VEHICLE_KEYS",
    "Leaf",
    "LeafReader",
    "check_keys",
    "domain_reasons",
    "parse_correlations",
    "used_normal_angle",
    "vehicle_state",
]

COEFFICIENT_KEYS = ("restitution", "impulse_ratio", "moment_restitution", "slip")
TOP_KEYS = (
    "model",
    "units",
    "impact",
    "vehicles",
    "title",
    "description",
    "notes",
    "comment",
    "correlations",
    "crash3",
    "impact_position",
)
IMPACT_KEYS = ("normal_angle", *COEFFICIENT_KEYS, "position")
VEHICLE_KEYS = (
    "name",
    "fixed",
    "mass",
    "weight",
    "yaw_inertia",
    "radius_of_gyration",
    "velocity",
    "yaw_rate",
    "impact_point",
    "heading",
    "final_velocity",
    "final_yaw_rate",
    "crush",
    "length",
    "width",
)
POLAR_KEYS = ("speed", "direction")
VEHICLE_FRAME_KEYS = ("forward", "left")
VEHICLE_POLAR_KEYS = ("distance", "angle")
_FORM_DIMENSIONS = {
    "speed": "speed",
    "direction": "angle",
    "forward": "length",
    "left": "length",
    "distance": "length",
    "angle": "angle",
}


def _forms(kind: str) -> tuple[tuple[str, ...], ...]:
    """The table forms of a vector field besides [x, y]."""
    return {"velocity": (POLAR_KEYS,), "impact_point": (VEHICLE_FRAME_KEYS, VEHICLE_POLAR_KEYS), "": ()}[kind]


#: Distribution kinds and their parameters (in the field's units).
DISTRIBUTIONS = {"normal": ("mean", "sd"), "uniform": ("low", "high"), "triangular": ("low", "mode", "high")}
#: Numeric entries of a ``crush`` table and their dimensions (units.DIMENSIONS);
#: its other entries are CRASH3's to check (impactsym.crash3).
CRUSH_LEAVES = {
    "A": "stiffness_A",
    "B": "stiffness_B",
    "width": "crush_length",
    "pdof": "angle",
    "moment_arm": "length",
    "radius_of_gyration": "length",
}
#: The domain of a leaf: what its nominal value and every draw must satisfy.
#: The largest |angle| a leaf may give, in degrees. An angle is read modulo
#: 360, but one beyond a million degrees is a slip of the keyboard (1e300 for
#: 100), not a direction: it is refused rather than reduced.
MAX_ANGLE_DEG = 1e6
DOMAINS = {
    "any": ("", lambda x: np.isfinite(x)),
    "positive": ("positive ", lambda x: x > 0.0),
    "nonnegative": ("non-negative ", lambda x: x >= 0.0),
}


def check_keys(data: Mapping, known: tuple[str, ...], path: str) -> None:
    """Raise a SceneError naming the first key of ``data`` not in ``known``,
    with the nearest known key as a suggestion."""
    for key in data:
        if key not in known:
            raise SceneError(unknown_key(str(key), known), f"{path}.{key}" if path else str(key))


def unknown_key(
    key: str, known: tuple[str, ...], word: str = "key", aliases: Mapping[str, str] | None = None
) -> str:
    """``unknown key; did you mean "restitution"?`` (difflib's nearest), or the list.

    ``word`` names what ``key`` is (``"column"`` for a batch). ``aliases`` maps
    other spellings to a known key (a scene's ``restitution`` to a batch's
    ``e``): a near miss of an alias suggests the key it stands for."""
    spellings = {name: name for name in known}
    spellings.update({alias: name for alias, name in (aliases or {}).items() if name in known})
    close = difflib.get_close_matches(key, tuple(spellings), n=1, cutoff=0.6)
    if close:
        target = spellings[close[0]]
        said = f" ({close[0]})" if target != close[0] else ""
        return f'unknown {word}; did you mean "{target}"{said}?'
    return f"unknown {word} (known here: {', '.join(known)})"


@dataclass(frozen=True)
class Leaf:
    """One numeric leaf in scene units: its path, dimension
    (units.DIMENSIONS), domain (``"any"``, ``"positive"``, ``"nonnegative"``),
    nominal value, and for an uncertain leaf its distribution ``kind`` and
    ``params`` (normal: mean, sd; uniform: low, high; triangular: low, mode,
    high)."""

    path: str
    dimension: str
    domain: str
    nominal: float
    kind: str | None = None
    params: tuple[float, ...] = ()


class LeafReader:
    """Reads the numeric leaves of one scene in its unit system and keeps them
    (:attr:`leaves`, path → :class:`Leaf`, in reading order)."""

    def __init__(self, units: str):
        self.units = units
        self.leaves: dict[str, Leaf] = {}

    def number(self, value: Any, path: str, dimension: str, domain: str = "any") -> float:
        """The nominal value of a leaf, in scene units; records the leaf."""
        if isinstance(value, Mapping):
            leaf = self._distribution(value, path, dimension, domain)
        else:
            leaf = Leaf(path, dimension, domain, self._plain(value, path, dimension, domain))
        _check_domain(leaf.nominal, value, path, domain)
        if dimension == "angle":
            _check_angle(leaf.nominal, path)
        self.leaves[path] = leaf
        return leaf.nominal

    def vector(self, value: Any, path: str, dimension: str, polar: str | None = None) -> None:
        """A 2-vector leaf pair: ``[x, y]`` (leaves ``path[0]``, ``path[1]``) or,
        for ``polar="velocity"``, ``{speed, direction}``, for
        ``polar="impact_point"``, ``{forward, left}`` or ``{distance, angle}``
        (leaves ``path.key``)."""
        if isinstance(value, (list, tuple)):
            if len(value) != 2:
                raise SceneError(f"must be a list of 2 numbers, got {show_value(value)}", path)
            for i, item in enumerate(value):
                self.number(item, f"{path}[{i}]", dimension)
            return
        forms = _forms(polar or ())
        if forms and isinstance(value, Mapping) and not set(value) & set(DISTRIBUTIONS):
            keys = next((form for form in forms if set(value) & set(form)), forms[0])
            check_keys(value, keys, path)
            for key in keys:
                if key not in value:
                    raise SceneError("missing", f"{path}.{key}")
                domain = "nonnegative" if key in ("speed", "distance") else "any"
                self.number(value[key], f"{path}.{key}", _FORM_DIMENSIONS[key], domain)
            return
        forms = "a list of 2 numbers" + "".join(f" or {{{', '.join(form)}}}" for form in forms)
        note = "; a distribution goes on each number" if isinstance(value, Mapping) else ""
        raise SceneError(f"must be {forms}{note}, got {show_value(value)}", path)

    def _plain(self, value: Any, path: str, dimension: str, domain: str) -> float:
        """A bare number or a unit string, in scene units."""
        if isinstance(value, str):
            try:
                return to_scene_units(value, path, dimension, self.units)
            except ValueError as exc:
                raise SceneError(str(exc), path) from None
        number = finite_float(value)
        if number is not None:
            return number
        word = DOMAINS[domain][0]
        raise SceneError(
            f"must be a {word}finite number (or a number with a unit, or a "
            f"distribution), got {show_value(value)}",
            path,
        )

    def _distribution(self, value: Mapping, path: str, dimension: str, domain: str) -> Leaf:
        """``{"normal": [mean, sd]}``, ``{"uniform": [low, high]}`` or
        ``{"triangular": [low, mode, high]}`` as a Leaf with its nominal value."""
        if len(value) != 1:
            raise SceneError(
                f"a distribution has exactly one key ({', '.join(DISTRIBUTIONS)}), "
                f"got {show_value(dict(value))}",
                path,
            )
        ((kind, raw),) = value.items()
        if kind not in DISTRIBUTIONS:
            raise SceneError(unknown_key(str(kind), tuple(DISTRIBUTIONS)), f"{path}.{kind}")
        names = DISTRIBUTIONS[kind]
        if not isinstance(raw, (list, tuple)) or len(raw) != len(names):
            raise SceneError(f"must be a list [{', '.join(names)}], got {show_value(raw)}", f"{path}.{kind}")
        params = tuple(self._plain(item, f"{path}.{kind}", dimension, "any") for item in raw)
        nominal = _check_distribution(kind, params, f"{path}.{kind}")
        return Leaf(path, dimension, domain, nominal, kind, params)


def _check_distribution(kind: str, params: tuple[float, ...], path: str) -> float:
    """The nominal value (mean, midpoint, mode) of valid distribution parameters."""
    if kind == "normal":
        if not params[1] > 0.0:
            raise SceneError(f"the standard deviation must be positive, got {params[1]:g}", path)
        return params[0]
    if kind == "uniform":
        if not params[0] < params[1]:
            raise SceneError(f"needs low < high, got [{params[0]:g}, {params[1]:g}]", path)
        return 0.5 * (params[0] + params[1])
    low, mode, high = params
    if not (low <= mode <= high and low < high):
        raise SceneError(f"needs low <= mode <= high and low < high, got [{low:g}, {mode:g}, {high:g}]", path)
    return mode


def _check_domain(nominal: float, raw: Any, path: str, domain: str) -> None:
    """A SceneError when the (nominal) value is outside the leaf's domain."""
    if domain != "any" and not DOMAINS[domain][1](nominal):
        word = DOMAINS[domain][0]
        shown = show_value(raw) if not isinstance(raw, Mapping) else f"{nominal:g} (the nominal value)"
        raise SceneError(f"must be a {word}finite number, got {shown}", path)


def _check_angle(degrees: float, path: str) -> None:
    """A SceneError for an angle beyond ±MAX_ANGLE_DEG degrees (scene units)."""
    if abs(degrees) > MAX_ANGLE_DEG:
        raise SceneError(
            f"{degrees:g} degrees is not a usable angle: give it within [-360, 360] "
            f"(at most {MAX_ANGLE_DEG:g} degrees in magnitude)",
            path,
        )


def domain_reasons(leaves: Mapping[str, Leaf], values: Mapping[str, Any], n: int) -> np.ndarray:
    """Per row, why the leaf ``values`` (arrays of draws) are out of their
    leaves' domains: ``""`` for a good row, else the first reason
    (``"vehicles[0].weight is not positive"``)."""
    reasons = np.full(n, "", dtype=object)
    for path, value in values.items():
        domain = leaves[path].domain
        bad = ~np.broadcast_to(DOMAINS["any"][1](value), (n,))
        word = "finite"
        if domain != "any":
            bad = bad | ~np.broadcast_to(DOMAINS[domain][1](value), (n,))
            word = DOMAINS[domain][0].strip()
        reasons[bad & (reasons == "")] = f"{path} is not {word}"
    return reasons


# --------------------------------------------------------------------------- alternative forms
# Each function takes leaf values by path (floats or NumPy arrays) and returns
# the scene-frame quantity; the same code serves the nominal scene and draws.


def vehicle_state(values: Mapping[str, Any], index: int, units: str) -> dict[str, Any]:
    """Vehicle ``index`` in scene-frame quantities: ``m`` (None when not
    given), ``I`` (None), ``v``, ``V`` (velocity, final velocity: (x, y) or
    None), ``w``, ``W`` (yaw rates, default 0), ``heading`` [deg] (None) and
    ``r`` (impact point, (x, y), default (0, 0))."""
    p = f"vehicles[{index}]"
    mass = _mass(values, p, units)
    heading = values.get(f"{p}.heading")
    return {
        "m": mass,
        "I": _yaw_inertia(values, p, mass),
        "v": _vector(values, f"{p}.velocity"),
        "V": _vector(values, f"{p}.final_velocity"),
        "w": values.get(f"{p}.yaw_rate", 0.0),
        "W": values.get(f"{p}.final_yaw_rate", 0.0),
        "heading": heading,
        "r": _impact_point(values, p, heading),
    }


def _mass(values: Mapping, p: str, units: str):
    """``mass``, or ``weight / g_n`` (g_n in the system's acceleration unit)."""
    if f"{p}.mass" in values:
        return values[f"{p}.mass"]
    if f"{p}.weight" in values:
        return values[f"{p}.weight"] / GRAVITY[units]
    return None


def _yaw_inertia(values: Mapping, p: str, mass):
    """``yaw_inertia``, or ``m·k²`` from ``radius_of_gyration`` k."""
    if f"{p}.yaw_inertia" in values:
        return values[f"{p}.yaw_inertia"]
    if f"{p}.radius_of_gyration" in values and mass is not None:
        return mass * values[f"{p}.radius_of_gyration"] ** 2
    return None


def _vector(values: Mapping, path: str):
    """``[x, y]``, or ``speed·(cos d, sin d)`` from ``{speed, direction}`` (d in degrees)."""
    if f"{path}[0]" in values:
        return values[f"{path}[0]"], values[f"{path}[1]"]
    if f"{path}.speed" in values:
        speed, direction = values[f"{path}.speed"], np.deg2rad(values[f"{path}.direction"])
        return speed * np.cos(direction), speed * np.sin(direction)
    return None


def _impact_point(values: Mapping, p: str, heading):
    """``[x, y]`` in the scene frame, or ``{forward, left}`` in the vehicle
    frame rotated by the heading; (0, 0) when not given."""
    path = f"{p}.impact_point"
    if f"{path}[0]" in values:
        return values[f"{path}[0]"], values[f"{path}[1]"]
    if f"{path}.forward" in values or f"{path}.distance" in values:
        forward, left = _vehicle_frame(values, path)
        angle = np.deg2rad(heading)
        c, s = np.cos(angle), np.sin(angle)
        return forward * c - left * s, forward * s + left * c
    return 0.0, 0.0


def _vehicle_frame(values: Mapping, path: str):
    """(forward, left) of a vehicle-frame impact point: given, or
    ``distance·(cos a, sin a)`` from ``{distance, angle}`` (a in degrees,
    counter-clockwise from the heading)."""
    if f"{path}.forward" in values:
        return values[f"{path}.forward"], values[f"{path}.left"]
    distance, angle = values[f"{path}.distance"], np.deg2rad(values[f"{path}.angle"])
    return distance * np.cos(angle), distance * np.sin(angle)


#: Rounding units of the floor under which n·(r1 - r2) does not decide the
#: normal's sense (a few operations of error each, with a margin of 4).
_SENSE_ROUNDING = 16.0


def used_normal_angle(given, r1, r2):
    """(Γ used [deg], flipped): the sense of the crush-surface normal that
    points from vehicle 1 toward vehicle 2, ``n·(r1 - r2) > 0`` (the centre of
    gravity of 2 seen from that of 1 is ``r1 - r2``). When the geometry cannot
    tell, Γ is kept: ``n·(r1 - r2) = 0`` (particles, no impact points, or the
    points along the crush surface's tangent) or within its rounding.

    Rounding floor: cos Γ and sin Γ of a rounded ``deg2rad(Γ)`` are each off by
    at most about ``eps·(1 + |Γ|)`` (Γ in radians), and the lever arms r1, r2
    (rotated from the vehicle frame) by ``eps·|r|`` per component, so a dot
    product within ``_SENSE_ROUNDING·eps·(1 + |Γ|)·(|r1| + |r2|)`` of zero is
    rounding: cos(-90°) = 6.1e-17, not 0, must not turn a normal round."""
    gamma = np.deg2rad(given)
    dot = np.cos(gamma) * (r1[0] - r2[0]) + np.sin(gamma) * (r1[1] - r2[1])
    arms = np.hypot(r1[0], r1[1]) + np.hypot(r2[0], r2[1])
    floor = _SENSE_ROUNDING * np.finfo(np.float64).eps * (1.0 + np.abs(gamma)) * arms
    flipped = dot < -floor
    return given + np.where(flipped, 180.0, 0.0), flipped


def parse_correlations(raw: Any, leaves: Mapping[str, Leaf]) -> tuple[tuple[str, str, float], ...]:
    """``[[path_a, path_b, rho], ...]``: each path an uncertain leaf, a != b,
    |rho| <= 1, each pair once, and a positive semi-definite matrix."""
    path = "correlations"
    if not isinstance(raw, list):
        raise SceneError(f"must be a list of [path_a, path_b, rho], got {show_value(raw)}", path)
    pairs, seen = [], set()
    for i, item in enumerate(raw):
        where = f"{path}[{i}]"
        if not (isinstance(item, (list, tuple)) and len(item) == 3):
            raise SceneError(f"must be [path_a, path_b, rho], got {show_value(item)}", where)
        a, b, rho = item
        for name in (a, b):
            _check_uncertain_path(name, leaves, where)
        if a == b:
            raise SceneError(f"correlates {a} with itself", where)
        if isinstance(rho, bool) or not isinstance(rho, numbers.Real) or not -1.0 <= rho <= 1.0:
            raise SceneError(f"rho must be a number in [-1, 1], got {show_value(rho)}", where)
        if frozenset((a, b)) in seen:
            raise SceneError(f"the pair {a}, {b} is given twice", where)
        seen.add(frozenset((a, b)))
        pairs.append((a, b, float(rho)))
    _check_positive_semidefinite(pairs)
    return tuple(pairs)


def _check_uncertain_path(name: Any, leaves: Mapping[str, Leaf], where: str) -> None:
    if not isinstance(name, str) or name not in leaves or leaves[name].kind is None:
        uncertain = tuple(p for p, leaf in leaves.items() if leaf.kind is not None)
        close = difflib.get_close_matches(str(name), uncertain, n=1, cutoff=0.6)
        hint = (
            f'; did you mean "{close[0]}"?'
            if close
            else f" (uncertain leaves: {', '.join(uncertain) or 'none'})"
        )
        raise SceneError(f"{show_value(name)} is not an uncertain leaf of the scene{hint}", where)


def _check_positive_semidefinite(pairs: list[tuple[str, str, float]]) -> None:
    """The correlation matrix of the named leaves must be a valid one."""
    names = sorted({name for a, b, _ in pairs for name in (a, b)})
    if not names:
        return
    index = {name: i for i, name in enumerate(names)}
    matrix = np.eye(len(names))
    for a, b, rho in pairs:
        matrix[index[a], index[b]] = matrix[index[b], index[a]] = rho
    if np.linalg.eigvalsh(matrix)[0] < -1e-12:
        raise SceneError(
            "the correlations do not form a valid correlation matrix (not positive semi-definite)",
            "correlations",
        )
