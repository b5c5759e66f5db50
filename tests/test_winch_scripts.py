"""The winch-baseline scripts (scripts/winch_frontier.py, scripts/baseline_table.py): table
formatting and configuration (fast), a one-point frontier run against its recorded figures and
a two-seed baseline table (slow). Every assertion states its tolerance.
"""

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest

from aerostat_gym.params import load_params

ROOT = Path(__file__).resolve().parents[1]


def load(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_frontier_table_format_and_targets():
    """One row formats to the 11-column Markdown table; the modal targets rise with wind speed
    and lie in (0, 1)."""
    fr = load("winch_frontier")
    row = {"wind_speed": 10.0, "policy": "modal", "brake": "off", "predicted_zeta": 0.6,
           "linear_fit_zeta": 0.568, "linear_drift_zeta": 0.6, "zeta": 0.545,
           "zeta_drift": 0.611, "peak_set_point_m_s": 0.716, "peak_reel_speed_m_s": 0.715,
           "length_wander_m": 8.49}
    lines = fr.table([row]).splitlines()
    assert len(lines) == 3 and lines[2].count("|") == 12
    assert "| 10 | modal | off | 0.600 | 0.568 | 0.600 | 0.545 | 0.611 |" in lines[2]
    for U, zs in fr.MODAL_ZETAS.items():
        assert all(0 < z < 1 for z in zs) and list(zs) == sorted(zs), U


@pytest.mark.slow
def test_frontier_point_reproduces():
    """The modal point at 10 m/s, zeta 0.6, 10 m swing: measured 1-mode 0.545 and drift fit
    0.611 (brake off), peak reel speed 0.715 m/s (each to 0.005)."""
    fr = load("winch_frontier")
    rows = fr.modal_curve_at(load_params(), 10.0, 10.0, (0.6,))
    off = next(r for r in rows if r["brake"] == "off")
    assert off["zeta"] == pytest.approx(0.545, abs=0.005)
    assert off["zeta_drift"] == pytest.approx(0.611, abs=0.005)
    assert off["peak_reel_speed_m_s"] == pytest.approx(0.715, abs=0.005)


@pytest.mark.slow
def test_baseline_table_two_seeds(tmp_path):
    """Two seeds per cell: every row carries mean and mean_ci (finite, low <= mean <= high) and
    every non-passive row a verdict; the aggregate has an IQM per policy."""
    bt = load("baseline_table")
    out = tmp_path / "t.json"
    bt.main(["--seeds", "2", "--json", str(out)])
    data = json.loads(out.read_text())
    for cell in data["cells"].values():
        for r in cell["rows"]:
            lo, hi = r["mean_ci"]
            assert math.isfinite(r["mean"]) and lo <= r["mean"] + 1e-12 and r["mean"] <= hi + 1e-12
            assert (r["policy"] == "passive") == ("verdict" not in r)
    assert {r["policy"] for r in data["aggregate"]} == {"passive", "tension", "lqr", "modal",
                                                        "lqg"}
    assert np.isfinite([r["iqm"] for r in data["aggregate"]]).all()
