"""Authority sweep (:mod:`aerostat_gym.agents.authority`): the target verdicts as closed forms,
and the sweep's episodes as the report suite's own, against the stored protocol table
(``agents/baseline_report/protocol.json``: the modal controller and the braked winch in light
turbulence at 8 m/s, 20 report seeds)."""

import json
from pathlib import Path

import numpy as np
import pytest

from aerostat_gym.agents.authority import (
    Design,
    authority_sweep,
    design_result,
    gust_markdown,
    reachable,
    target_verdict,
)
from aerostat_gym.agents.evaluate import cells_result, evaluate_policy
from aerostat_gym.agents.policies import load_policy
from aerostat_gym.params import load_params

PROTOCOL = Path(__file__).resolve().parents[1] / "agents" / "baseline_report" / "protocol.json"


def test_target_verdicts_closed_form():
    """a = 0.8 b exactly gives the interval [0, 0] (met); a = b > 0 gives 0.2 b > 0 (missed);
    paired differences of both signs straddle zero (indistinguishable)."""
    b = np.array([1.0, 2.0, 3.0, 4.0])
    v, ci = target_verdict(0.8 * b, b, 0.8)
    assert v == "met" and ci == pytest.approx([0.0, 0.0], abs=1e-12)
    v, ci = target_verdict(b, b, 0.8)
    assert v == "missed" and ci[0] > 0.0
    v, _ = target_verdict(b + np.array([-1.0, 1.0, -1.0, 1.0]), b, 1.0)
    assert v == "indistinguishable"
    assert target_verdict([1.0], [1.0], 1.0) == ("n/a", None)


def _stored(cell_scenario: str, speed: float, label: str, metric: str) -> float:
    proto = json.loads(PROTOCOL.read_text())
    cell = next(c for c in proto["cells"]
                if c["scenario"] == cell_scenario and c["wind_speed"] == speed)
    return cell["policies"][label][metric]["mean"]


def test_sweep_rows_are_the_evaluators_episodes_smoke():
    """Fast version of the next test: the sweep over two report seeds at 8 m/s, light
    turbulence, against the evaluator's run of the same cells (the default modal design is the
    ``modal`` baseline): the row's mean RMS displacement and its ratio to the braked winch's
    equal the evaluator's (rel 1e-12), and the recover row's damping is the evaluator's."""
    params, seeds = load_params(), (100, 101)
    sweep = authority_sweep(params, designs=(Design("modal", "modal"),), gusty_speeds=(8.0,),
                            seeds=seeds, recover_speeds=(10.0,), scenarios=("gusty_light",),
                            report_speeds=(8.0,))
    (row,) = sweep["gusty"]
    (rec,) = sweep["recover"]
    cells = {"gusty_light": ([8.0], list(seeds)), "recover": ([10.0], list(seeds[:1]))}

    def episodes(name):
        result = cells_result(load_policy(name, params=params), name, cells, 0.01, params)
        return {sc: d["episodes"] for sc, d in result["scenarios"].items()}

    modal, passive = episodes("modal"), episodes("passive")
    mean = np.mean([e["rms_x_m"] for e in modal["gusty_light"]])
    assert row["rms_x_m"] == pytest.approx(mean, rel=1e-12)
    assert row["rms_x_ratio"] == pytest.approx(
        mean / np.mean([e["rms_x_m"] for e in passive["gusty_light"]]), rel=1e-12)
    assert rec["pendulum_zeta"] == pytest.approx(modal["recover"][0]["pendulum_zeta"], rel=1e-12)


@pytest.mark.slow
def test_sweep_reproduces_the_report_suite():
    """The default modal design in light turbulence at 8 m/s over the 20 report seeds: mean RMS
    along-wind displacement and its ratio to the braked winch's equal the stored protocol's
    (1.658 m, 0.931 with 0.7.17's turbulence; 1.591 m, 0.929 before) within 1e-9 relative: the
    sweep runs the report's own episodes."""
    sweep = authority_sweep(load_params(), designs=(Design("modal", "modal"),),
                            scenarios=("gusty_light",), report_speeds=(8.0,))
    (row,) = sweep["gusty"]
    modal = _stored("gusty_light", 8.0, "modal", "rms_x_m")
    passive = _stored("gusty_light", 8.0, "passive", "rms_x_m")
    assert row["rms_x_m"] == pytest.approx(modal, rel=1e-9)
    assert row["rms_x_ratio"] == pytest.approx(modal / passive, rel=1e-9)
    # 0.931 x passive misses the 0.8 target with a paired interval above zero
    assert row["targets"]["rms_x_m"]["verdict"] == "missed"
    cell = reachable(sweep)[0]
    assert cell["best_design"] == "modal" and cell["all_targets"] == []
    assert "| gusty_light | modal | 0.931 | **no** |" in gust_markdown(sweep, 8.0)
    (rec10,) = [r for r in sweep["recover"] if r["wind_speed"] == 10.0]
    assert rec10["pendulum_zeta"] == pytest.approx(_stored("recover", 10.0, "modal",
                                                           "pendulum_zeta"), rel=1e-9)


def test_design_result_is_the_evaluators_episode():
    """A design's result on the report-tiny suite holds the same episodes as the evaluator's
    run of the same controller (the default modal design is the ``modal`` baseline): returns
    equal to 1e-12 relative, so the aggregate pools it with the baselines' results as their
    peer; a suite without the report's sensor noise is refused."""
    params = load_params()
    mine = design_result(Design("modal", "modal"), params, "report-tiny")
    ref = evaluate_policy("modal", "report-tiny", params=params)
    assert set(mine["scenarios"]) == set(ref["scenarios"])
    for sc, d in mine["scenarios"].items():
        a = [(e["wind_speed"], e["seed"], e["return"]) for e in d["episodes"]]
        b = [(e["wind_speed"], e["seed"], e["return"]) for e in ref["scenarios"][sc]["episodes"]]
        assert [x[:2] for x in a] == [x[:2] for x in b]
        assert [x[2] for x in a] == pytest.approx([x[2] for x in b], rel=1e-12)
    with pytest.raises(ValueError, match="noisy suites"):
        design_result(Design("modal", "modal"), params, "tiny")
