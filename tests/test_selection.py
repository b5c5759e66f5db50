"""Choosing a trained policy on the validation suite (:mod:`aerostat_gym.agents.selection`):
the rule's verdicts on constructed results whose answer is known in closed form, the tie-break
on the aggregate, and the validation suite disjoint from the report suite."""

import json
import math

import numpy as np
import pytest

from aerostat_gym import jsonout
from aerostat_gym.agents.evaluate import SUITES, suite_seeds
from aerostat_gym.agents.protocol import aggregate
from aerostat_gym.agents.report import load_results
from aerostat_gym.agents.selection import (
    GUST_TARGETS,
    RECOVER_TARGETS,
    select,
    selection_markdown,
    target_checks,
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
