"""Friction laws of the cross-check variants (frictionless, Tresca, slip-dependent, the scene's own), as FreeFEM gets them."""
from __future__ import annotations

from pathlib import Path

from oracle.errors import SideFailed


COULOMB_LAWS = ("constant", "ramp", "table")  # the laws the FreeFEM reference takes with Coulomb's bound


def scene_law_depends_on_slip(scene: dict) -> bool:
    fr = scene.get("friction", {})
    return fr.get("law", "none") in ("ramp", "table") and float(fr.get("slip_bound", 0.0)) > 0


def expand_variants(names, scene: dict) -> list[str]:
    out = []
    for v in names:
        v = v.strip()
        if v == "all" and scene.get("friction", {}).get("model", "tresca") == "coulomb":
            out += ["frictionless"] + (["coulomb"] if scene.get("friction", {}).get("law") in COULOMB_LAWS else [])
        elif v == "all":
            out += ["frictionless", "tresca"] + (["slipdep"] if scene_law_depends_on_slip(scene) else [])
        elif v:
            out.append(v)
    return out


def law_F(law: dict, t: float) -> float:
    """F(t) of an ff_law dict: the same formula as contact3d's FrictionLaw and contact_ref.edp."""
    if law["kind"] == 1:
        if t <= law["t0"]:
            return law["high"]
        if t >= law["t0"] + 2.0 / law["param"]:
            return law["low"]
        return law["high"] - (law["high"] - law["low"]) * law["param"] / 2.0 * (t - law["t0"])
    if law["kind"] == 2:
        T, F = law["T"], law["F"]
        if t <= T[0]:
            return F[0]
        if t >= T[-1]:
            return F[-1]
        j = next(k for k in range(1, len(T)) if T[k] > t)
        return F[j - 1] + (F[j] - F[j - 1]) * (t - T[j - 1]) / (T[j] - T[j - 1])
    return 0.0


def slipdep_law(fr: dict, scene_path: Path) -> dict:
    """FreeFEM law of the scene's ramp/table [friction] table (contact3d's defaults for absent keys)."""
    g = float(fr.get("slip_bound", 0.0))
    law = fr.get("law", "none")
    if law == "ramp":
        d = {"kind": 1, "g": g, "high": float(fr.get("high", 0.3)), "low": float(fr.get("low", 0.2)),
             "t0": float(fr.get("t0", 1e-5)), "param": float(fr.get("param", 6e4))}
        d["s"] = g * max(d["high"], d["low"])
        return d
    if law == "table":
        pts = fr.get("points")
        if not isinstance(pts, list) or not pts or not all(isinstance(p, list) and len(p) == 2 for p in pts):
            raise SideFailed(f"{scene_path}: friction.points must be a list of [t, F] pairs")
        d = {"kind": 2, "g": g, "T": [float(p[0]) for p in pts], "F": [float(p[1]) for p in pts]}
        d["s"] = g * max(d["F"])
        return d
    raise SideFailed(f"{scene_path}: variant slipdep needs friction.law = ramp or table (have {law!r})")


def law_label(law: dict) -> str:
    if law["kind"] == 1:
        return (f"ramp F(|u_t|): high={law['high']:g}, low={law['low']:g}, t0={law['t0']:g}, "
                f"param={law['param']:g}, g={law['g']:g}")
    if law["kind"] == 2:
        return f"table F(|u_t|) ({len(law['T'])} points), g={law['g']:g}"
    return f"s={law['s']:g}"


def perturb_law(law: dict, items: list[str]) -> dict:
    """--perturb-freefem-law KEY=VALUE (negative tests): change the FreeFEM side's law only (a table's
    KEY F sets F at every point: a constant law's coefficient)."""
    law = dict(law)
    keys = [x for x in ("high", "low", "t0", "param", "g", "F") if x in law]
    for kv in items:
        k, sep, v = kv.partition("=")
        k = k.strip()
        if not sep or k not in keys:
            raise SideFailed(f"--perturb-freefem-law {kv!r}: expected KEY=VALUE with KEY one of {', '.join(keys)}")
        law[k] = [float(v)] * len(law["F"]) if k == "F" else float(v)
    if law.get("coulomb"):
        law["s"] = None  # F·λ_n: known after the solve
    elif law["kind"] == 1:
        law["s"] = law["g"] * max(law["high"], law["low"])
    elif law["kind"] == 2:
        law["s"] = law["g"] * max(law["F"])
    return law


def law_parameters(fr: dict, law: dict) -> dict:
    """The keys of the scene's [friction] table that define its ramp (kind 1) or table (kind 2) law."""
    keys = ("high", "low", "t0", "param") if law["kind"] == 1 else ("points",)
    return {k: fr[k] for k in keys if k in fr}


def variant_friction(scene: dict, variant: str, F: float, scene_path: Path) -> tuple[dict, dict, str]:
    """The [friction] table for the variant, the FreeFEM law ({"kind": 0, "s": F*g} for a constant
    bound; kind 1 ramp / 2 table with "g" and the law's parameters, "s" = g*max F; for the variant
    coulomb also "coulomb": True and "s" None, the bound being F·λ_n), a label."""
    fr = scene.get("friction", {})
    g = float(fr.get("slip_bound", 0.0))
    if variant == "frictionless":
        return {"law": "none"}, {"kind": 0, "s": 0.0}, "frictionless"
    if variant == "tresca":
        if g <= 0:
            raise SideFailed(f"{scene_path}: variant tresca needs friction.slip_bound > 0")
        return ({"law": "constant", "value": F, "slip_bound": g}, {"kind": 0, "s": F * g},
                f"Tresca F={F:g}, g={g:g}")
    if variant == "slipdep":
        if g <= 0:
            raise SideFailed(f"{scene_path}: variant slipdep needs friction.slip_bound > 0")
        law = slipdep_law(fr, scene_path)
        return {"law": fr["law"], "slip_bound": g, **law_parameters(fr, law)}, law, law_label(law)
    if variant == "coulomb_constant":
        # Coulomb's bound F·λ_n with one F (--F): to FreeFEM a table whose two points have that F
        law = {"kind": 2, "g": 1.0, "T": [0.0, 1.0], "F": [F, F], "coulomb": True, "s": None}
        return {"model": "coulomb", "law": "constant", "value": F}, law, f"Coulomb F={F:g}"
    if variant == "coulomb" and fr.get("law") == "constant":  # the scene's own F
        return variant_friction(scene, "coulomb_constant", float(fr.get("value", F)), scene_path)
    if variant == "coulomb":
        # the scene's slip-dependent law with Coulomb's bound F(φ)·λ_n instead of F(φ)·g
        law = dict(slipdep_law(dict(fr, slip_bound=1.0), scene_path), g=1.0, coulomb=True)
        law["s"] = None  # the bound's scale is F·λ_n: known after the solve
        table = {"model": "coulomb", "law": fr["law"], **law_parameters(fr, law)}
        return table, law, "Coulomb " + law_label(law).replace(", g=1", "")
    if variant == "scene":
        law = fr.get("law", "none")
        if fr.get("model", "tresca") == "coulomb" and law in COULOMB_LAWS:
            table, ffl, label = variant_friction(scene, "coulomb", F, scene_path)
            return table, ffl, label + " (scene)"
        if fr.get("model", "tresca") == "coulomb" and law != "none":
            raise SideFailed(f"{scene_path}: Coulomb with law {law!r} has no FreeFEM reference")
        if law == "none" or g == 0:
            return {"law": "none"}, {"kind": 0, "s": 0.0}, "frictionless (scene)"
        if law == "constant":
            Fs = float(fr["value"])
            return ({"law": "constant", "value": Fs, "slip_bound": g}, {"kind": 0, "s": Fs * g},
                    f"Tresca F={Fs:g}, g={g:g} (scene)")
        if law in ("ramp", "table"):
            table, ffl, label = variant_friction(scene, "slipdep", F, scene_path)
            return table, ffl, label + " (scene)"
        raise SideFailed(f"{scene_path}: friction law {law!r} has no FreeFEM reference")
    raise SideFailed(f"unknown variant {variant!r}")
