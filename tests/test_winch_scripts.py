"""The winch-frontier script (scripts/winch_frontier.py): table formatting, configuration and
the frontier figure from synthetic rows (fast) and a one-point frontier run against its recorded
figures (slow). Every assertion states its tolerance.
"""

import json

import pytest

from aerostat_gym.agents.frontier import saturated_speeds
from aerostat_gym.params import load_params


def test_frontier_table_format_and_targets(load_script):
    """One row formats to the 8-column Markdown table (designed zeta blank where there is none);
    the modal targets rise with wind speed and lie in (0, 1)."""
    fr = load_script("winch_frontier")
    row = {"wind_speed": 10.0, "policy": "modal", "kind": "modal", "designed_zeta": 0.6,
           "zeta": 0.545, "zeta_drift": 0.611, "peak_set_point_m_s": 0.716,
           "peak_reel_speed_m_s": 0.715, "length_wander_m": 8.49}
    learned = {**row, "policy": "shipped", "kind": "learned", "designed_zeta": None}
    lines = fr.table([row, learned]).splitlines()
    assert len(lines) == 4 and all(line.count("|") == 9 for line in lines)
    assert lines[2] == "| 10 | modal | 0.600 | 0.545 | 0.611 | 0.715 | 0.716 | 8.49 |"
    assert lines[3].startswith("| 10 | shipped |  | 0.545 |")
    for U, zs in fr.MODAL_ZETAS.items():
        assert all(0 < z < 1 for z in zs) and list(zs) == sorted(zs), U


def _synthetic_rows():
    rows = []
    for U, z0 in ((5.0, 0.15), (10.0, 0.28), (15.0, 0.36)):
        def r(policy, kind, designed, zeta, peak, U=U):
            return {"wind_speed": U, "policy": policy, "kind": kind, "designed_zeta": designed,
                    "zeta": zeta, "zeta_drift": zeta, "peak_reel_speed_m_s": peak,
                    "peak_set_point_m_s": peak, "length_wander_m": 1.0}
        rows += [r("passive", "passive", z0, z0, 0.0), r("tension", "baseline", None, z0, 0.1),
                 r("lqr", "baseline", z0 + 0.05, z0 + 0.05, 0.3),
                 r("lqg", "baseline", z0 + 0.05, z0 + 0.04, 0.1),
                 r("shipped", "learned", None, z0 + 0.06, 0.5)]
        rows += [r("modal", "modal", z0 + dz, z0 + dz, 0.2 + 3 * dz) for dz in (0.02, 0.1, 0.2)]
    return rows


def test_frontier_plot_writes_png(tmp_path, load_script):
    """Synthetic rows draw three panels (one per wind speed) into a PNG of more than 10 kB; the
    5 m/s authority bound is a horizontal line there only; the modal runs saturating the winch
    mark that speed (frontier.saturated_speeds)."""
    fr = load_script("winch_frontier")
    rows = _synthetic_rows()
    limits = [{"wind_speed": U, "zeta": z, "peak_set_point_m_s": 1.0, "authority": U == 5.0}
              for U, z in ((5.0, 0.22), (10.0, 0.80), (15.0, 0.99))]
    out = tmp_path / "frontier.png"
    fig = fr.plot(rows, limits, out, swing=10.0)
    assert out.exists() and out.stat().st_size > 10_000
    assert len(fig.axes) == 3
    assert [a.get_title() for a in fig.axes] == ["U = 5 m/s", "U = 10 m/s", "U = 15 m/s"]
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert {"modal controller", "modal limit (linear)", "passive (braked winch)",
            "LQR (full state)", "LQG (sensor noise)", "tension feedback", "shipped PPO (learned)",
            "authority bound (winch saturates)"} <= set(texts)
    sat = [dict(r, peak_reel_speed_m_s=1.0) if r["wind_speed"] == 5.0 and r["kind"] == "modal"
           else r for r in rows]
    assert saturated_speeds(rows) == [] and saturated_speeds(sat) == [5.0]


def test_frontier_point_reproduces(load_script):
    """The modal point at 10 m/s, zeta 0.6, 10 m swing, shipped winch: measured 1-mode 0.545 and
    drift fit 0.611, peak reel speed 0.715 m/s (each to 0.005). (3 s: in the default run.)"""
    fr = load_script("winch_frontier")
    (row,) = fr.modal_curve_at(load_params(), 10.0, 10.0, (0.6,))
    assert row["designed_zeta"] == 0.6
    assert row["zeta"] == pytest.approx(0.545, abs=0.005)
    assert row["zeta_drift"] == pytest.approx(0.611, abs=0.005)
    assert row["peak_reel_speed_m_s"] == pytest.approx(0.715, abs=0.005)


def test_poi_split_script_writes_its_table(tmp_path, capsys, load_script):
    """scripts/poi_split.py on a constructed two-cell report prints and writes the table and
    rows the library gives (a calm cell won outright, a tied turbulent cell: P 0.75, and so the
    bound); an unknown label is one line naming it."""
    def res(label, calm, gusty):
        ep = {"wind_speed": 10.0, "seed": 1, "return": calm}
        return {"label": label, "suite": "report", "score": 0.0, "scenarios": {
            "recover": {"episodes": [ep, {**ep, "seed": 2}]},
            "gusty": {"episodes": [{**ep, "return": gusty}, {**ep, "seed": 2, "return": gusty}]}}}

    report = tmp_path / "report.json"
    report.write_text(json.dumps([res("passive", -2.0, -20.0), res("a", -1.0, -20.0)]))
    split = load_script("poi_split")
    split.main([str(report), "--x", "a", "--y", "passive", "--markdown",
                str(tmp_path / "s.md"), "--json", str(tmp_path / "s.json")])
    row = json.loads((tmp_path / "s.json").read_text())[0]
    assert (row["calm"], row["turbulent"], row["p"], row["bound"]) == (1.0, 0.5, 0.75, 0.75)
    assert (tmp_path / "s.md").read_text() in capsys.readouterr().out
    with pytest.raises(SystemExit, match="'zz'"):
        split.main([str(report), "--x", "zz", "--y", "passive"])
    # --lost: passive loses the calm cell outright to a, so a P over a is capped at 1/2
    split.main([str(report), "--x", "passive", "--y", "a", "--lost", "--json",
                str(tmp_path / "l.json")])
    lost = json.loads((tmp_path / "l.json").read_text())[0]
    assert lost["cells"] == [["recover", 10.0]] and lost["cap"] == 0.5
