"""The time step of a scene: given in units of t_c, or chosen from an energy tolerance.

t_c = sqrt(m delta_c / F_c) (Wada et al. 2007, eq. 49) is the time a contact takes to
move by delta_c at v0; the plugin prints it at every run and refuses dt > 0.4 t_c
(benchmarks/stability.py). Within the stable range the energy error of a collision
grows as a power of dt and of the impact speed; ``benchmarks/tradeoff.py`` measures
it on ensembles of 2D and 3D collisions and writes the fit

    max |dE| / E_imp  <=  C (dt / t_c)^p (v_col / v0)^q

to ``timestep_fit.json`` (the worst run of each ensemble lies on or below it). It bounds
the frictional model. The frictionless model's error hardly depends on v_col and grows
with the aggregates' size, so ``benchmarks/timestep_frictionless.py`` fits it a bound of
its own, with and without damping, from the tradeoff study, the 3D BPCA study's sizes
and the 2 x 50000 run:

    max |dE| / E_imp  <=  C_f (dt / t_c)^p_f (N_total / 2000)^s

and a frictionless scene's dt meets both bounds. ``choose`` inverts them for a tolerance;
the choice is held to [DT_MIN, DT_MAX] t_c.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

#: the papers' time step (Wada et al. 2007, sec. 4): |dE| / E_imp below 1e-4
PAPER_DT = 0.014
DT_MIN, DT_MAX = 0.002, 0.1      # t_c; above DT_MAX the plugin warns
#: what dt "auto" aims at without a tolerance (jkrdt setup --dt auto, a campaign's spec)
AUTO_TOLERANCE = 1e-4
#: the plugin refuses dt above this (pair_style jkr/dt dt_check; benchmarks/stability.py)
DT_STABLE = 0.4
FIT_FILE = Path(__file__).with_name("timestep_fit.json")


def fit() -> dict:
    """The study's fit (``benchmarks/tradeoff.py``)."""
    return json.loads(FIT_FILE.read_text())


def frictionless_bound(damped: bool) -> dict:
    """The frictionless model's bound (``benchmarks/timestep_frictionless.py``)."""
    return fit()["frictionless"]["damped" if damped else "undamped"]


def bounds(v_over_v0: float, model: str = "frictional", n_total: int | None = None,
           damped: bool = False) -> list[tuple[float, float, str]]:
    """The bounds that hold for a scene, each as (log10 of its prefactor at this scene,
    its exponent of dt / t_c, where it comes from): max |dE| / E_imp <= 10^a (dt/t_c)^p."""
    f = fit()
    out = [(f["log10_C"] + f["q"] * math.log10(v_over_v0), f["p"],
            f"the fit {10 ** f['log10_C']:.3g} (dt/t_c)^{f['p']:.2f} (v/v0)^{f['q']:.2f} of "
            "benchmarks/tradeoff")]
    if model == "frictionless":
        if n_total is None or n_total < 2:
            raise ValueError("the frictionless model's bound needs the scene's grain count")
        b = frictionless_bound(damped)
        out.append((b["log10_C"] + b["s"] * math.log10(n_total / b["n_ref"]), b["p"],
                    f"the {'damped ' if damped else ''}frictionless bound "
                    f"{10 ** b['log10_C']:.3g} (dt/t_c)^{b['p']:.2f} (N/{b['n_ref']})^"
                    f"{b['s']:.2f} at N = {n_total} of benchmarks/timestep_frictionless"))
    return out


def predicted_error(dt_over_tc: float, v_over_v0: float, model: str = "frictional",
                    n_total: int | None = None, damped: bool = False) -> float:
    """The bound on max |dE| / E_imp at ``dt_over_tc``: the tradeoff fit, and for the
    frictionless model the larger of it and the frictionless bound at ``n_total`` grains."""
    return max(10 ** (a + p * math.log10(dt_over_tc))
               for a, p, _ in bounds(v_over_v0, model, n_total, damped))


def choose(tolerance: float, v_col: float, v0: float, model: str = "frictional",
           n_total: int | None = None, damped: bool = False) -> tuple[float, str]:
    """(dt / t_c, the reason) for a max |dE| / E_imp of ``tolerance`` at ``v_col`` under
    ``model`` (for 'frictionless', of ``n_total`` grains, ``damped`` or not): the largest
    dt that every bound of the scene allows."""
    if not 0 < tolerance < 1:
        raise ValueError(f"--tolerance is a relative energy error in (0, 1) (got {tolerance})")
    if not v_col > 0:
        raise ValueError(f"the impact speed must be > 0 to choose dt (got {v_col})")
    v = v_col / v0
    dt, why = min((10 ** ((math.log10(tolerance) - a) / p), why)
                  for a, p, why in bounds(v, model, n_total, damped))
    held = min(max(dt, DT_MIN), DT_MAX)
    reason = (f"dt = {held:.4g} t_c chosen for max |dE|/E_imp <= {tolerance:g} at v_col = "
              f"{v_col:g} m/s = {v:.3g} v0 from {why}")
    if held != dt:
        reason += f" (the bound gave {dt:.3g} t_c, held to [{DT_MIN}, {DT_MAX}])"
    return held, reason


def parse(value: str) -> float | str:
    """A --dt value: a number of t_c, or 'auto'."""
    if value == "auto":
        return value
    try:
        dt = float(value)
    except ValueError:
        raise ValueError(f"--dt takes a time step in units of t_c or 'auto' (got {value!r})")
    return check(dt, "--dt ")


def check(dt: float, name: str = "dt ") -> float:
    """``dt`` (t_c) if the plugin runs it, else a ValueError naming the range."""
    if not dt > 0:
        raise ValueError(f"{name}must be > 0 (in units of t_c; got {dt:g})")
    if dt > DT_STABLE:
        raise ValueError(f"{name}must be at most {DT_STABLE} t_c, where velocity Verlet still "
                         f"holds a contact (got {dt:g}; the papers' is {PAPER_DT})")
    return dt
