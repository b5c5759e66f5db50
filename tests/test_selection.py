"""Choosing a trained policy on the validation suite (:mod:`aerostat_gym.agents.selection`):
the rule's verdicts on constructed results whose answer is known in closed form, the tie-break
on the aggregate, the task-return gate before them, and the validation suite disjoint from the
report suite."""

import json
import math

import numpy as np
import pytest

from aerostat_gym import jsonout
from aerostat_gym.agents.evaluate import SUITES, suite_seeds
from aerostat_gym.agents.protocol import aggregate
from aerostat_gym.agents.report import load_results
from aerostat_gym.agents.returns import RETURN_SEEDS
from aerostat_gym.agents.selection import (
    GATE_SEEDS,
    GUST_TARGETS,
    RECOVER_TARGETS,
    select,
    selection_markdown,
    target_checks,
    task_gate,
)

SEEDS = list(range(7000, 7010))
#: Small, seed-dependent wiggles: paired differences of a constant offset plus these have a
#: spread, so their intervals are proper bootstrap intervals, yet stay within +-0.001.
WIGGLE = 1e-3 * np.sin(np.arange(len(SEEDS)))

PASSIVE = {"pendulum_zeta": 0.30, "pitch_zeta": 0.40, "length_wander_m": 0.0,
           "rms_x_m": 2.0, "rms_pitch_rad": 0.010, "peak_tension_N": 3000.0,
           "terminated": 0.0, "return": -100.0}
MODAL = {**PASSIVE, "pendulum_zeta": 0.60, "length_wander_m": 4.0, "rms_x_m": 1.5,
         "return": -80.0}


def _result(label: str, values: dict, wiggle: float = 0.0) -> dict:
    """A validation-suite result: every cell of recover, gusty_light and gusty at two speeds,
    each metric its value plus ``wiggle`` x the seed's wiggle (the return's scale x 100; the
    termination flag has none)."""
    scale = {"return": 100.0, "terminated": 0.0}

    def episodes(u):
        return [{"wind_speed": u, "seed": s,
                 **{k: v + wiggle * w * scale.get(k, 1.0)
                    for k, v in values.items()}}
                for s, w in zip(SEEDS, WIGGLE, strict=True)]
    return {"label": label, "suite": "validation",
            "scenarios": {sc: {"episodes": episodes(7.5) + episodes(12.5)}
                          for sc in ("recover", "gusty_light", "gusty")}}


def _baselines():
    return [_result("passive", PASSIVE), _result("modal", MODAL), _result("lqg", MODAL)]


def _met(checks, target):
    return [k["met"] for k in checks if k["target"] == target]


def test_target_kinds_in_closed_form():
    """A candidate at 0.95 x modal's pendulum damping, 0.01 above passive's pitch damping, 1 m
    less wander than modal, RMS x at 0.7 x passive's, pitch and tension below passive's, meets
    every target at both speeds; one at 0.85 x modal's damping, 0.01 below passive's pitch
    damping and 1 m more wander misses those three and keeps the rest."""
    by = {r["label"]: r for r in _baselines()}
    good = _result("good", {**PASSIVE, "pendulum_zeta": 0.57, "pitch_zeta": 0.41,
                            "length_wander_m": 3.0, "rms_x_m": 1.4, "rms_pitch_rad": 0.009,
                            "peak_tension_N": 2900.0}, wiggle=1.0)
    checks = target_checks(good, by)
    assert len(checks) == 2 * len(RECOVER_TARGETS) + 2 * 2 * len(GUST_TARGETS)
    assert all(k["met"] for k in checks)
    bad = _result("bad", {**PASSIVE, "pendulum_zeta": 0.51, "pitch_zeta": 0.39,
                          "length_wander_m": 5.0, "rms_x_m": 1.4, "rms_pitch_rad": 0.009,
                          "peak_tension_N": 2900.0}, wiggle=1.0)
    checks = target_checks(bad, by)
    assert _met(checks, "pendulum zeta >= 0.9 x modal") == [False, False]
    assert _met(checks, "pitch zeta not worse than passive") == [False, False]
    assert _met(checks, "length wander <= modal") == [False, False]
    assert _met(checks, "pendulum zeta above passive") == [True, True]
    assert sum(k["met"] for k in checks) == len(checks) - 6


def test_rms_x_fraction_and_ties():
    """RMS x exactly 0.8 x passive's meets the 0.8 target (interval [0, 0]); 0.9 x misses it.
    Two candidates meeting the same targets are ranked by the aggregate IQM."""
    by = {r["label"]: r for r in _baselines()}
    at = _result("at", {**PASSIVE, "rms_x_m": 1.6})
    above = _result("above", {**PASSIVE, "rms_x_m": 1.8})
    assert _met(target_checks(at, by), "RMS x <= 0.8 x passive") == [True] * 4
    assert _met(target_checks(above, by), "RMS x <= 0.8 x passive") == [False] * 4
    hi = _result("hi", {**MODAL, "return": -70.0})
    lo = _result("lo", {**MODAL, "return": -90.0})
    sel = select([lo, hi], _baselines())
    assert sel["chosen"] == "hi"
    a, b = sel["ranking"]
    assert a["targets_met"] == b["targets_met"]
    # the score is return / |passive's mean return|: -0.7 and -0.9 with no spread
    assert a["iqm"] == pytest.approx(-0.7, abs=1e-12) and b["iqm"] == pytest.approx(-0.9)
    assert "| 1 | hi |" in selection_markdown(sel)


#: Gate returns over 20 seeds: the incumbent's (a spread of episode difficulty), and a small
#: per-challenger wiggle, so that paired differences have proper intervals.
GATE_SPREAD = -1000.0 - 500.0 * np.cos(np.arange(20))
GATE_WIGGLE = 5.0 * np.sin(3.0 * np.arange(20)) * np.cos(np.arange(20))


def _gate_returns(**offsets):
    """The incumbent's returns and each challenger's, given as offsets from them per seed."""
    return {"incumbent": GATE_SPREAD, **{k: GATE_SPREAD + v for k, v in offsets.items()}}


def test_task_gate_in_closed_form():
    """A challenger level with the incumbent (a zero-mean wiggle off it) passes; one 100 below it
    on every seed fails; one that loses 3000 on a single seed in 20 and gains 10 on the rest
    passes (mean -140, but one episode is no evidence: the interval reaches above zero), and
    losing it on three seeds fails (mean -441). The incumbent passes with no difference."""
    k = np.arange(20)
    gate = task_gate(_gate_returns(level=GATE_WIGGLE, below=GATE_WIGGLE - 100.0,
                                   one_bad=np.where(k == 0, -3000.0, 10.0) + GATE_WIGGLE,
                                   three_bad=np.where(k < 3, -3000.0, 10.0) + GATE_WIGGLE),
                     "incumbent")
    assert gate["incumbent"] == {"passed": True, "mean": pytest.approx(GATE_SPREAD.mean()),
                                 "minus_incumbent": None}
    assert gate["level"]["passed"] and not gate["below"]["passed"]
    est, lo, hi = gate["below"]["minus_incumbent"]
    assert est == pytest.approx(-100.0 + GATE_WIGGLE.mean(), abs=1e-9) and lo < est < hi < 0.0
    est, lo, hi = gate["one_bad"]["minus_incumbent"]
    assert gate["one_bad"]["passed"] and lo < est < 0.0 <= hi
    assert est == pytest.approx((-3000.0 + 19 * 10.0) / 20 + GATE_WIGGLE.mean(), abs=1e-9)
    assert not gate["three_bad"]["passed"]
    assert gate["three_bad"]["minus_incumbent"][0] == pytest.approx(
        (-9000.0 + 17 * 10.0) / 20 + GATE_WIGGLE.mean(), abs=1e-9)
    with pytest.raises(ValueError, match=r"needs the incumbent 'shipped'"):
        task_gate(_gate_returns(), "shipped")
    with pytest.raises(ValueError, match=r"share their seeds; lengths \[19, 20\]"):
        task_gate({**_gate_returns(), "short": np.zeros(19)}, "incumbent")


def test_the_gate_ranks_before_the_targets():
    """A challenger meeting more targets that is worse than the incumbent on the task ranks
    after the incumbent; without the gate the order is the targets' (the rule before 0.7.20)."""
    more = _result("more", {**MODAL, "pendulum_zeta": 0.57})
    incumbent = _result("incumbent", {**PASSIVE, "pendulum_zeta": 0.57})
    gate = task_gate(_gate_returns(more=np.full(20, -200.0) + GATE_WIGGLE), "incumbent")
    ungated = select([more, incumbent], _baselines())
    gated = select([more, incumbent], _baselines(), gate=gate)
    assert ungated["chosen"] == "more" and gated["chosen"] == "incumbent"
    assert [r["label"] for r in gated["ranking"]] == ["incumbent", "more"]
    assert gated["ranking"][1]["targets_met"] > gated["ranking"][0]["targets_met"]
    table = selection_markdown(gated)
    assert "| 1 | incumbent | incumbent (-1028) |" in table  # the mean of GATE_SPREAD
    assert "| 2 | more | **worse** (-200 [" in table
    with pytest.raises(ValueError, match=r"no verdict for \['more'\]"):
        select([more, incumbent], _baselines(), gate={"incumbent": gate["incumbent"]})


def test_gate_seeds_are_their_own():
    """The gate never reads an episode of the suites, the returns table or the training runs'
    first seeds."""
    assert not set(GATE_SEEDS) & (suite_seeds("validation") | suite_seeds("report")
                                  | set(RETURN_SEEDS) | set(range(1000)))
    assert len(GATE_SEEDS) == 200


def test_task_gate_script_writes_what_select_policy_reads(tmp_path, capsys, load_script):
    """scripts/task_gate.py on two gate seeds: the returns of the incumbent, a challenger (two
    baselines standing in for trained models) and a baseline for the record are written under
    their labels, the challenger's difference printed; select_policy's reader merges two such
    files and refuses a label twice or files of other seeds or incumbents."""
    gate_script, sel_script = load_script("task_gate"), load_script("select_policy")
    out = tmp_path / "a.json"
    rec = gate_script.main(["--incumbent", "inc", "--policy", "modal_lqg", "--label", "inc",
                            "--policy", "modal", "--label", "cand", "--baselines", "passive",
                            "--seeds", "2", "--out", str(out)])
    assert rec["seeds"] == list(GATE_SEEDS[:2]) and rec["task"] == "TetheredAerostatRealistic-v0"
    assert list(rec["returns"]) == ["passive", "inc", "cand"] and rec["incumbent"] == "inc"
    assert all(len(r) == 2 and all(np.isfinite(r)) for r in rec["returns"].values())
    printed = capsys.readouterr().out.splitlines()
    assert printed[1].startswith("inc: mean return ") and printed[1].endswith("the incumbent")
    assert printed[2].startswith("cand: mean return ") and "minus the incumbent" in printed[2]
    other = tmp_path / "b.json"
    other.write_text(json.dumps({**rec, "returns": {"second": rec["returns"]["cand"]}}))
    merged, incumbent = sel_script.read_gate([out, other])
    assert incumbent == "inc" and merged["second"] == merged["cand"] and len(merged) == 4
    other.write_text(json.dumps({**rec, "returns": {"cand": rec["returns"]["cand"]}}))
    with pytest.raises(ValueError, match=r"give \['cand'\] twice"):
        sel_script.read_gate([out, other])
    for change in ({"seeds": [1, 2]}, {"incumbent": "cand"}):
        other.write_text(json.dumps({**rec, **change, "returns": {}}))
        with pytest.raises(ValueError, match="ran different tasks, seeds or incumbents"):
            sel_script.read_gate([out, other])
    other.write_text(json.dumps({"returns": {}}))
    with pytest.raises(ValueError, match=r"not a scripts/task_gate.py record: no \['incumbent', "
                                         r"'seeds', 'task'\]"):
        sel_script.read_gate([other])
    with pytest.raises(SystemExit, match=r"--label: 1 label\(s\) for 2 --policy"):
        gate_script.main(["--incumbent", "x", "--policy", "modal", "--policy", "lqr",
                          "--label", "x", "--out", str(out)])
    with pytest.raises(SystemExit, match="--seeds must lie in"):
        gate_script.main(["--incumbent", "x", "--policy", "modal", "--seeds", "1",
                          "--out", str(out)])


def test_the_stored_selection_keeps_the_shipped_policy_behind_the_gate(load_script):
    """agents/ppo_training/selection.json, the record of the shipped choice, agrees with the
    gate recomputed from its stored returns: its first-ranked candidate is the incumbent, whose
    run is the shipped training run; every challenger's stored verdict is the recomputed one
    (matched by its mean return, to 1e-9); the ten relief seeds fail, no other candidate does."""
    from aerostat_gym.resources import shipped_path

    sel = json.loads(shipped_path("ppo_training", "selection.json").read_text())
    returns, incumbent = load_script("select_policy").read_gate(
        [shipped_path("ppo_training", f"task_gate_{part}.json") for part in "ab"])
    command = shipped_path("ppo_training", "command.txt").read_text().split()
    assert command[command.index("--run-dir") + 1].endswith("/" + incumbent.split("/")[0])
    verdicts = task_gate(returns, incumbent)
    first = sel["ranking"][0]
    assert sel["chosen"] == first["label"] and first["gate"]["minus_incumbent"] is None
    assert first["gate"]["mean"] == pytest.approx(verdicts[incumbent]["mean"], abs=1e-9)
    by_mean = {round(v["mean"], 6): v for v in verdicts.values()}
    assert len(by_mean) == len(verdicts)
    failed = []
    for row in sel["ranking"]:
        recomputed = by_mean[round(row["gate"]["mean"], 6)]
        assert row["gate"]["passed"] == recomputed["passed"], row["label"]
        if row["gate"]["minus_incumbent"] is not None:
            assert row["gate"]["minus_incumbent"] == pytest.approx(
                recomputed["minus_incumbent"], abs=1e-9)
        if not row["gate"]["passed"]:
            failed.append(row["label"])
    assert len(sel["ranking"]) == 21 and len(failed) == 10
    assert all("relief" in label for label in failed)


def test_selection_refuses_other_suites_and_missing_baselines():
    cand = _result("c", MODAL)
    report = {**cand, "suite": "report"}
    with pytest.raises(ValueError, match="validation suite only"):
        select([report], _baselines())
    with pytest.raises(ValueError, match="missing \\['lqg'\\]"):
        select([cand], _baselines()[:2])


def test_validation_suite_is_disjoint_from_the_report_suite():
    """The choice never sees a report case: no seed in common, and in every scenario no wind
    speed in common."""
    assert not suite_seeds("validation") & suite_seeds("report")
    assert set(SUITES["validation"]) == set(SUITES["report"])
    for scenario, (speeds, _) in SUITES["validation"].items():
        assert not set(speeds) & set(SUITES["report"][scenario][0]), scenario


def test_aggregate_refuses_a_label_twice():
    """Two results under one label would merge into one score matrix of twice the cells (the
    authority aggregate's designs "modal" and "lqr" share the baselines' names)."""
    with pytest.raises(ValueError, match="labels must be distinct"):
        aggregate([_result("passive", PASSIVE), _result("modal", MODAL), _result("modal", MODAL)])


def test_load_results_names_what_is_wrong(tmp_path):
    """Several runs' report.json read back as one {label: result}; a label twice or a wanted
    label missing is an error naming it."""
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps([_result("passive", PASSIVE)]))
    b.write_text(json.dumps([_result("modal", MODAL)]))
    got = load_results([a, b], ["modal"])
    assert list(got) == ["passive", "modal"] and got["modal"]["suite"] == "validation"
    with pytest.raises(ValueError, match="'passive' appears twice"):
        load_results([a, a])
    with pytest.raises(ValueError, match=r"\['lqg'\]; labels there: \['passive', 'modal'\]"):
        load_results([a, b], ["lqg"])


def test_a_report_json_is_strict_json_and_reads_back_with_its_nans(tmp_path):
    """report.json writes a metric that is NaN (no lateral swing to fit) as null, which every
    JSON reader parses (Python's bare NaN token is refused by strict parsers); load_results
    reads it back as NaN, and the end reason's None stays None."""
    from aerostat_gym.agents.report import jsonable

    episode = {"wind_speed": 10.0, "seed": 1, "rms_x_m": 2.5, "lateral_pendulum_zeta": math.nan,
               "ended": None}
    result = {"label": "passive", "suite": "tiny",
              "scenarios": {"recover": {"episodes": [episode]}}}
    path = tmp_path / "report.json"
    path.write_text(jsonout.dumps(jsonable([result]), indent=1))
    raw = json.loads(path.read_text(), parse_constant=lambda t: pytest.fail(f"{t} in JSON"))
    assert raw[0]["scenarios"]["recover"]["episodes"][0]["lateral_pendulum_zeta"] is None
    back = load_results([path])["passive"]["scenarios"]["recover"]["episodes"][0]
    assert math.isnan(back["lateral_pendulum_zeta"]) and back["ended"] is None
    assert back["rms_x_m"] == 2.5 and back["seed"] == 1
