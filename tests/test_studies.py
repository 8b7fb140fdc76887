"""Quick variants of the time-step studies whose full results are committed in
benchmarks/stability/ and benchmarks/tradeoff/: the scripts run, and their numbers obey
what the integrator fixes."""

import json
import math
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def study(script, tmp_path, *args):
    subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), "--quick", *args],
                   check=True, timeout=600, capture_output=True, cwd=tmp_path)


def test_stability_limit_of_frictional_networks(tmp_path):
    # omega dt = 2 for the stiffest oscillators (sliding coupled to rotation) lies between
    # 0.40 and 0.45 t_c whatever the material: t_c carries the whole material dependence
    study("stability.py", tmp_path, "--out", str(tmp_path / "s.json"))
    found = json.loads((tmp_path / "s.json").read_text())
    assert found["stable_dt_over_tc"]["ice frictional"] == 0.4
    assert found["stable_dt_over_tc"]["quartz frictional"] == 0.4
    for r in found["rows"]:
        if r["model"] == "frictional" and r["dt_over_tc"] == 0.5:
            assert r["max_dE_over_K0"] > 10 or r["stopped"]           # blown up


def test_tradeoff_energy_error_order(tmp_path):
    # velocity Verlet is second order for smooth forces; contact events and clamps add
    # first-order terms, so an aggregate collision's error grows as dt^p with 1 < p < 2.5
    study("tradeoff.py", tmp_path, "--out", str(tmp_path / "t"), "--work", str(tmp_path / "w"))
    found = json.loads((tmp_path / "t" / "tradeoff.json").read_text())
    assert (tmp_path / "t" / "tradeoff.png").stat().st_size > 0
    for scene in ("bcca2d", "bpca3d_fric", "bpca3d_free"):
        rows = sorted((r for r in found["summary"] if r["scene"] == scene),
                      key=lambda r: r["dt_over_tc"])
        assert all(r["settled"] == r["runs"] for r in rows)
        lo, hi = rows[0], rows[-1]
        p = math.log(hi["energy_error_mean"] / lo["energy_error_mean"]) / math.log(
            hi["dt_over_tc"] / lo["dt_over_tc"])
        assert 1.0 < p < 2.5, (scene, p)
