"""The frozen evaluation protocol (issue 17): scenarios, suites, seeds, the new metrics and the
protocol's paired verdicts and aggregate."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from aerostat_gym.agents.evaluate import (
    SCENARIOS,
    SUITE_OBS_NOISE,
    SUITES,
    episode_metrics,
    run_scenario,
    suite_seeds,
)
from aerostat_gym.agents.metrics import response_metrics
from aerostat_gym.agents.poi_split import lost_by_all, lost_markdown, poi_split, split_markdown
from aerostat_gym.agents.policies import PassivePolicy
from aerostat_gym.agents.protocol import cell_markdown, protocol, protocol_markdown
from aerostat_gym.agents.returns import RETURN_SEEDS
from aerostat_gym.envs.config import DEFAULT_WIND_RANGE

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def starts():
    """First recorded sample (x, y, pitch) of every recover scenario, braked winch, 10 m/s."""
    out = {}
    for name, sc in SCENARIOS.items():
        if sc.free:
            ep = run_scenario(PassivePolicy(), name, [10.0], [5000])
            out[name] = (ep.x[0, 0], ep.y[0, 0], ep.pitch[0, 0])
    return out


def test_recover_scenarios_start_displaced_as_stated(starts):
    """Cross-wind: y(0) is the stated 10 m / 1 m / 7.07 m / 0.707 m. Along-wind: x(0) is the
    stated swing plus the CM shift of the same pitch kick (measured in the cross-wind scenario
    with that kick: -0.58 m at 0.05 rad), and no cross-wind displacement."""
    d = 10.0 / math.sqrt(2.0)
    for name, y0 in (("recover_cross", 10.0), ("recover_cross_small", 1.0),
                     ("recover_combined", d), ("recover_combined_small", d / 10)):
        assert starts[name][1] == pytest.approx(y0, rel=2e-3), name
    assert starts["recover_cross"][0] == pytest.approx(-0.58, abs=0.02)
    for name, ref, x0 in (("recover", "recover_cross", 10.0),
                          ("recover_small", "recover_cross_small", 1.0),
                          ("recover_combined", "recover_cross", d),
                          ("recover_combined_small", "recover_cross_small", d / 10)):
        assert starts[name][0] - starts[ref][0] == pytest.approx(x0, rel=1e-2), name
    for name in ("recover", "recover_small"):
        assert abs(starts[name][1]) < 1e-9, name
    assert starts["recover_cross"][2] == pytest.approx(0.05, rel=1e-2)
    assert starts["recover_cross_small"][2] == pytest.approx(0.005, rel=1e-2)


def test_new_metrics_match_closed_forms():
    """RMS of a sine over whole periods is A / sqrt 2; wander of a ramp a t is a t_end and its
    RMS a sqrt(mean t^2); the lateral pendulum fit recovers a synthetic damped sinusoid."""
    t = np.arange(0.0, 100.0, 0.1)  # 10 whole periods of 10 s
    zeros = np.zeros_like(t)
    y = 3.0 * np.sin(2 * np.pi * t / 10.0)
    q = 0.02 * np.cos(2 * np.pi * t / 10.0)
    ramp = 0.05 * t
    m = response_metrics(t, zeros + 1e-3 * np.sin(t), zeros, zeros + 1e3, zeros, y_disp=y,
                         pitch_rate=q, length_dev=-ramp)
    assert m["rms_y_m"] == pytest.approx(3.0 / math.sqrt(2.0), rel=1e-9)
    assert m["rms_pitch_rate_rad_s"] == pytest.approx(0.02 / math.sqrt(2.0), rel=1e-9)
    assert m["length_wander_m"] == pytest.approx(0.05 * t[-1], rel=1e-12)
    assert m["rms_length_m"] == pytest.approx(0.05 * math.sqrt(np.mean(t**2)), rel=1e-12)
    assert math.isnan(m["lateral_pendulum_zeta"])  # not asked for
    zeta, period = 0.1, 80.0
    wn = 2 * np.pi / period
    tl = np.arange(0.0, 180.0, 0.2)
    yl = 5.0 * np.exp(-zeta * wn * tl) * np.cos(wn * math.sqrt(1 - zeta**2) * tl)
    z = np.zeros_like(tl)
    m = response_metrics(tl, z + 1e-3 * np.sin(tl), z, z, z, y_disp=yl, fit_lateral=True)
    assert m["lateral_pendulum_zeta"] == pytest.approx(zeta, rel=1e-3)
    assert m["lateral_pendulum_period_s"] == pytest.approx(period, rel=1e-3)


def test_report_suite_seeds_are_held_out():
    """Report seeds: 20 per cell, none used in training (SB3 seeds environment i with
    --seed + i, for training seeds 0-4 of each shipped hyperparameter file: the shipped policy's
    seed and the seed-spread runs), by another suite or by the task-returns table; 16 m/s lies
    outside the training wind range; noise on."""
    training = set()
    for path in list((ROOT / "agents" / "hyperparams").glob("*.yml")) + [
            ROOT / "agents" / "ppo_training" / "hyperparams.yml"]:
        for block in yaml.safe_load(path.read_text()).values():
            if isinstance(block, dict) and "n_envs" in block:
                training |= {s + i for s in range(5) for i in range(int(block["n_envs"]))}
    shipped_seed = json.loads((ROOT / "agents" / "ppo_training"
                               / "training_summary.json").read_text())["seed"]
    assert shipped_seed in range(5)
    assert training == set(range(36))  # ppo: 32 envs; sac, td3: 8
    report = suite_seeds("report")
    assert report == set(range(5000, 5020))
    assert report & training == set()
    assert report & set(RETURN_SEEDS) == set()
    for other in ("damping", "tiny", "small", "full"):
        assert report & suite_seeds(other) == set(), other
    assert suite_seeds("report-tiny") <= report
    cells = SUITES["report"]
    assert len(cells) == 9 and all(len(seeds) == 20 for _, seeds in cells.values())
    assert max(cells["gusty_severe"][0]) == 16.0 > DEFAULT_WIND_RANGE[1]
    assert SUITE_OBS_NOISE["report"] == 0.01 and "tiny" not in SUITE_OBS_NOISE


def _episode(seed, u=10.0, **metrics):
    base = {"wind_speed": u, "seed": seed, "return": -100.0, "rms_x_m": 2.0, "rms_y_m": 1.0,
            "rms_pitch_rad": 0.01, "rms_pitch_rate_rad_s": 0.001, "peak_tension_N": 5e3,
            "length_wander_m": 0.0, "winch_energy_J": 0.0, "terminated": 0.0,
            "pendulum_zeta": 0.28, "pitch_zeta": 0.3}
    base.update(metrics)
    return base


def _result(label, scenario, episodes):
    return {"label": label, "suite": "report-tiny", "score": 0.0,
            "scenarios": {scenario: {"episodes": episodes}}}


def test_protocol_verdicts_on_constructed_results():
    """Two policies, two seeds: a policy whose RMS x is lower by 0.5 m and pendulum damping
    higher by 0.1 on every seed is 'better' on both; equal metrics are 'indistinguishable';
    higher peak tension is 'worse'; a uniformly higher return wins every pair (P = 1)."""
    seeds = (7, 8)
    passive = _result("passive", "recover", [_episode(s, rms_x_m=2.0 + 0.1 * s) for s in seeds])
    better = _result("mine", "recover", [
        _episode(s, rms_x_m=1.5 + 0.1 * s, pendulum_zeta=0.38, peak_tension_N=6e3,
                 **{"return": -50.0 + s}) for s in seeds])
    proto = protocol([passive, better])
    paired = proto["cells"][0]["paired"]["mine"]["passive"]
    assert paired["rms_x_m"]["verdict"] == "better"
    assert paired["rms_x_m"]["diff"] == pytest.approx(-0.5)
    assert paired["pendulum_zeta"]["verdict"] == "better"
    assert paired["pitch_zeta"]["verdict"] == "indistinguishable"
    assert paired["rms_y_m"]["verdict"] == "indistinguishable"
    assert paired["peak_tension_N"]["verdict"] == "worse"
    agg = proto["aggregate"]
    assert agg["mine"]["p_improvement"]["passive"]["p"] == 1.0
    assert agg["passive"]["p_improvement"]["mine"]["p"] == 0.0
    assert agg["passive"]["iqm"] == pytest.approx(-1.0)
    table = cell_markdown(proto["cells"][0])
    assert "better: pend. zeta long., RMS x, return; worse: peak T" in table
    same = protocol([passive, _result("twin", "recover", passive["scenarios"]["recover"]
                                      ["episodes"])])
    assert {d["verdict"] for d in same["cells"][0]["paired"]["twin"]["passive"].values()} \
        == {"indistinguishable"}
    assert "| twin | 0.280 | 0.300 | indistinguishable |" in protocol_markdown(same)
    one_seed = protocol([_result(r["label"], "recover", r["scenarios"]["recover"]["episodes"][:1])
                         for r in (passive, better)])
    assert {d["verdict"] for d in one_seed["cells"][0]["paired"]["mine"]["passive"].values()} \
        == {"n/a"}
    assert "| n/a (fewer than 2 paired seeds: no interval) |" in protocol_markdown(one_seed)


def test_protocol_refuses_unpaired_seeds():
    a = _result("passive", "gusty", [_episode(1), _episode(2)])
    b = _result("lqr", "gusty", [_episode(1), _episode(3)])
    with pytest.raises(ValueError, match="different seeds"):
        protocol([a, b])


def test_noisy_episode_records_clean_tension_and_differs_by_seed():
    """With sensor noise the tension history is the noise-free one (a braked winch in calm
    air: identical over seeds) and the policy-visible noise makes the seeds of the tension
    feedback differ after a 10 m swing (measured: winch energy 739 J and 770 J at seeds 5000
    and 5001, 10 m/s; after the 1 m swing its noisy commands stay inside the brake's dead band
    and every seed is the same episode)."""
    from aerostat_gym.agents.policies import TensionFeedbackPolicy

    kw = {"obs_noise": 0.01}
    ep = run_scenario(PassivePolicy(), "recover_small", [10.0], [5000, 5001], env_kwargs=kw)
    clean = run_scenario(PassivePolicy(), "recover_small", [10.0], [5000])
    np.testing.assert_array_equal(ep.tension[0], clean.tension[0])
    np.testing.assert_array_equal(ep.tension[0], ep.tension[1])
    tf = run_scenario(TensionFeedbackPolicy(), "recover", [10.0], [5000, 5001],
                      env_kwargs=kw)
    m0, m1 = episode_metrics(tf, 0), episode_metrics(tf, 1)
    assert abs(m0["winch_energy_J"] - m1["winch_energy_J"]) > 10.0
    assert m0["terminated"] == 0.0 and "length_wander_m" in m0


def test_evaluate_writes_the_protocol_tables(tmp_path, capsys):
    """``aerostat-gym evaluate --suite report-tiny`` with two policies writes protocol.md (one
    table per cell, the aggregate) and report.json with the paired differences; the terminal
    shows no image links."""
    import json

    from aerostat_gym.cli import main

    assert main(["evaluate", "--policy", "passive", "--policy", "tension", "--suite",
                 "report-tiny", "--out", str(tmp_path), "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert "![" not in printed and "protocol.md" in printed
    md = (tmp_path / "protocol.md").read_text()
    assert "### gusty_severe, 16 m/s, 2 seeds" in md
    assert "### recover_cross_small, 10 m/s, 2 seeds" in md
    assert "| tension |" in md and "P(better than passive)" in md
    data = json.loads((tmp_path / "report.json").read_text())
    paired = data[1]["scenarios"]["gusty_severe"]["paired"][0]
    assert paired["wind_speed"] == 16.0
    assert paired["passive"]["rms_x_m"]["verdict"] in ("better", "worse", "indistinguishable")
    assert data[0]["obs_noise"] == 0.01


def test_rounding_level_differences_are_indistinguishable():
    """A point interval of 8e-18 m (two deterministic episodes differing by rounding) is no
    difference; one of 1 mm on both seeds is."""
    from aerostat_gym.agents.protocol import paired_verdict
    from aerostat_gym.agents.protocol_stats import Interval

    assert paired_verdict(Interval(8e-18, 8e-18, 8e-18, 0.95, 20), "rms_y_m") \
        == "indistinguishable"
    assert paired_verdict(Interval(1e-3, 1e-3, 1e-3, 0.95, 20), "rms_y_m") == "worse"
    assert paired_verdict(Interval(-1e-3, -2e-3, -5e-4, 0.95, 20), "rms_y_m") == "better"
    assert paired_verdict(Interval(0.01, -0.01, 0.03, 0.95, 20), "pendulum_zeta") \
        == "indistinguishable"


def test_aggregate_pools_the_cells_with_the_most_seeds():
    """The tiny suite's recover cells have one seed and its gusty cell two: the aggregate pools
    the gusty cell only (a score matrix needs equal runs per column)."""
    def res(label, ret):
        return {"label": label, "suite": "tiny", "score": 0.0, "scenarios": {
            "recover": {"episodes": [_episode(0, **{"return": ret})]},
            "gusty": {"episodes": [_episode(s, **{"return": ret * s}) for s in (100, 101)]}}}

    proto = protocol([res("passive", -2.0), res("mine", -1.0)])
    assert proto["aggregate_cells"] == ["gusty 10 m/s"]
    assert proto["aggregate"]["mine"]["iqm"] == pytest.approx(100.5 / -201.0)
    assert "1 of 2 cells with the most seeds" in protocol_markdown(proto)


def test_condensed_view_marks_the_paired_verdicts():
    """protocol_summary on a constructed two-policy cell: the mean and interval as printed, a
    policy uniformly better than passive on RMS x marked with the up-triangle, and the aggregate
    row present."""
    from aerostat_gym.agents.protocol import aggregate_markdown
    from aerostat_gym.agents.protocol_summary import metric_table

    entry = {"mean": 5.0, "ci": [4.0, 6.0]}
    cell = {"scenario": "gusty", "wind_speed": 8.0,
            "policies": {"passive": {"rms_x_m": {"mean": 7.0, "ci": [7.0, 7.0]}},
                         "lqr": {"rms_x_m": entry}},
            "paired": {"lqr": {"passive": {"rms_x_m": {"verdict": "better"}}}}}
    proto = {"cells": [cell],
             "aggregate": {"passive": {"iqm": -1.0, "iqm_ci": [-1.1, -0.9],
                                       "p_improvement": {"lqr": {"p": 0.2, "ci": [0.1, 0.3]}}},
                           "lqr": {"iqm": -0.5, "iqm_ci": [-0.6, -0.4],
                                   "p_improvement": {"passive": {"p": 0.8, "ci": [0.7, 0.9]}}}}}
    table = metric_table(proto, [("gusty", "rms_x_m", 1.0, 1, (8.0,))])
    assert table.splitlines()[2] == "| `gusty` | 8 | 7.0 | 5.0 [4.0, 6.0] ▲ |"
    agg = aggregate_markdown(proto).splitlines()
    assert agg[3] == "| lqr | -0.500 [-0.600, -0.400] | 0.80 [0.70, 0.90] | - |"


def test_pooled_training_seeds_keep_seed_blocks():
    """Three training seeds of one configuration, returns -50 (seed 0), -60, -70 on every
    episode, against passive at -100: pooled, the configuration has 3 x 4 runs per cell in
    training-seed blocks; its IQM is the middle half of (-50 x 4, -60 x 4, -70 x 4), -60 / 100
    (exact), it beats passive in every pair (P = 1), and the per-seed table of
    :func:`seed_spread` gives each seed's own IQM (-0.5, -0.6, -0.7)."""
    from aerostat_gym.agents.protocol import aggregate, pool_training_seeds
    from aerostat_gym.agents.seed_spread import seed_spread, seed_spread_markdown

    seeds = (1, 2, 3, 4)
    passive = _result("passive", "gusty", [_episode(s) for s in seeds])
    runs = [_result(f"s{g}", "gusty", [_episode(s, **{"return": -50.0 - 10 * g}) for s in seeds])
            for g in range(3)]
    pooled = pool_training_seeds(runs, "cfg")
    assert pooled["groups"] == 3 and pooled["members"] == ["s0", "s1", "s2"]
    rets = [e["return"] for e in pooled["scenarios"]["gusty"]["episodes"]]
    assert rets == [-50.0] * 4 + [-60.0] * 4 + [-70.0] * 4
    agg = aggregate([passive, pooled])["aggregate"]
    assert agg["cfg"]["iqm"] == pytest.approx(-0.6, abs=1e-12)
    assert agg["cfg"]["training_seeds"] == 3
    assert agg["cfg"]["p_improvement"]["passive"] == {"p": 1.0, "ci": [1.0, 1.0]}
    lo, hi = agg["cfg"]["iqm_ci"]
    assert -0.7 - 1e-12 <= lo < -0.6 < hi <= -0.5 + 1e-12  # the seed blocks spread it
    spread = seed_spread([passive], runs, "cfg")
    assert [r["iqm"] for r in spread["per_seed"]] == pytest.approx([-0.5, -0.6, -0.7])
    assert spread["iqm_over_seeds"]["median"] == pytest.approx(-0.6)
    assert "min -0.700, median -0.600, max -0.500" in seed_spread_markdown(spread)
    with pytest.raises(ValueError, match="distinct"):
        pool_training_seeds([runs[0], runs[0]], "cfg")


def test_policy_labels_stay_distinct():
    """Two runs' ppo_final.zip are told apart by their run directory; a baseline keeps its
    name, the shipped policy its file stem; the same policy twice is refused."""
    from aerostat_gym.agents.report import policy_labels

    assert policy_labels(["passive", "shipped", "runs/a/ppo_final.zip", "runs/b/ppo_final.zip",
                          "x/model.zip"]) == ["passive", "ppo_tethered_aerostat", "a/ppo_final",
                                              "b/ppo_final", "model"]
    with pytest.raises(ValueError, match="listed twice"):
        policy_labels(["lqr", "lqr"])


def test_given_labels_name_models_of_separate_runs():
    """``evaluate --label`` names each policy (so that the ``ppo_final`` of runs evaluated one
    at a time can be read back together); a count that differs from the policies', an empty
    label or one given twice is refused, naming the fault."""
    from aerostat_gym.agents.report import given_labels, run_evaluations

    assert given_labels(["s4", "passive"], ["runs/s4/ppo_final.zip", "passive"]) == ["s4",
                                                                                     "passive"]
    for labels, needle in ((["a"], "1 label(s) for 2 --policy"), (["a", " "], "label 2 is empty"),
                           (["a", "a"], "'a' is given twice")):
        with pytest.raises(ValueError, match=re.escape(needle)):
            given_labels(labels, ["passive", "lqr"])
    rows = run_evaluations(["passive"], "tiny", progress=False, labels=["braked"])
    assert [r["label"] for r in rows] == ["braked"]


def test_poi_split_on_constructed_results():
    """Two calm cells and one turbulent cell, four seeds: X beats Y by 1 in one calm cell on
    every seed (P 1), loses by 1 in the other (P 0), and in the turbulent cell is better by 1 on
    every seed while the seeds spread by 100: the unpaired P there is the Mann-Whitney value
    (X's seed k beats Y's seeds k to 4: 10 of 16 pairs), the paired win rate 1; the bound
    counts both calm cells as won: (1 + 1 + 10/16) / 3."""
    seeds = (1, 2, 3, 4)

    def res(label, calm_a, calm_b, shift):
        return {"label": label, "suite": "report", "score": 0.0, "scenarios": {
            "recover": {"episodes": [_episode(s, **{"return": calm_a}) for s in seeds]},
            "recover_small": {"episodes": [_episode(s, **{"return": calm_b}) for s in seeds]},
            "gusty": {"episodes": [_episode(s, **{"return": -100.0 * s + shift})
                                   for s in seeds]}}}

    results = [res("passive", -60.0, -6.0, -50.0), res("x", -50.0, -6.0, 1.0),
               res("y", -51.0, -5.0, 0.0)]
    split = poi_split(results, "x", "y")
    assert split["calm"] == 0.5 and split["calm_cells"] == 2 and split["turbulent_cells"] == 1
    assert split["turbulent"] == 10 / 16 and split["turbulent_paired_win"] == 1.0
    assert split["p"] == pytest.approx((1.0 + 0.0 + 10 / 16) / 3)
    assert split["bound"] == pytest.approx((2.0 + 10 / 16) / 3)
    assert split["calm_lost"] == 1  # recover_small: each of x's episodes below each of y's
    assert "| x | y | 0.54 | 0.50 (2) | 0.62 (1) | 1.00 | 0.88 | 1 |" in split_markdown([split])
    with pytest.raises(ValueError, match="'z'"):
        poi_split(results, "z", "y")
    # lost by all: x and passive both lose recover_small outright to y (passive also loses
    # recover, x does not), so one of the three cells is lost by both: cap 2 / 3
    lost = lost_by_all(results, ["x", "passive"], "y")
    assert lost["cells"] == [("recover_small", 10.0)] and lost["cap"] == pytest.approx(2 / 3)
    assert lost_by_all(results, ["passive"], "y")["cells"] == [("recover", 10.0),
                                                               ("recover_small", 10.0)]
    assert "| y | 1: recover_small 10 | 0.67 |" in lost_markdown([lost])
    with pytest.raises(ValueError, match="'z'"):
        lost_by_all(results, ["z"], "y")
