"""The Ray integration: parameter ranges, the Monte Carlo study (serial and Ray paths give the
same numbers), its statistics, the tune command, and the one-line exit when the extra is
missing. Ray tests share the session's two-CPU instance (tests/conftest.py)."""

from __future__ import annotations

import csv
import json
import math
import sys

import numpy as np
import pytest
from scipy import stats

from aerostat_gym.agents.evaluate import evaluate_policy
from aerostat_gym.agents.hyperparams import load_hyperparams
from aerostat_gym.analysis.sensitivity import DAMPING_SPEEDS, default_knobs
from aerostat_gym.analysis.sensitivity import stability_figures as sensitivity_evaluate
from aerostat_gym.cli import main
from aerostat_gym.cli.scale import format_summary
from aerostat_gym.envs.config import DEFAULT_RANDOMIZATION
from aerostat_gym.extras import MissingExtraError, require
from aerostat_gym.params import ParameterError, load_params
from aerostat_gym.scale.mc_report import correlations, stability_table, stable_everywhere, summarize
from aerostat_gym.scale.montecarlo import (
    MODES,
    PERIOD_KEYS,
    SampleResult,
    Study,
    draw_valid,
    draw_values,
    evaluate_sample,
    run_ray,
    run_serial,
    sample_params,
    studies_identical,
)
from aerostat_gym.scale.ranges import ParameterRange, estimated_ranges, range_disagreements
from aerostat_gym.scale.stats import point_biserial, wilson_interval
from aerostat_gym.scale.tune import (
    TuneSpaceError,
    apply_sample,
    config_table,
    load_space,
    tune_space,
)

BASE = load_params()
FAST_SPEEDS = (1.0, 2.0, 10.0)  # [m/s] a short sweep: the low-wind lateral pendulum and 10 m/s


# --- ranges ---------------------------------------------------------------------------------------


def test_documented_ranges_are_the_sensitivity_knobs():
    ranges = estimated_ranges(BASE)
    knobs = default_knobs(BASE)
    assert [r.key for r in ranges] == [k.key for k in knobs]
    np.testing.assert_array_equal([(r.low, r.high) for r in ranges], [(k.low, k.high) for k in knobs])
    eta = next(r for r in ranges if r.key == "hull.eta_k")
    assert (eta.low, eta.high, eta.nominal) == (0.1, 0.5, 0.4)


def test_randomization_ranges_and_their_disagreements():
    ranges = {r.key: r for r in estimated_ranges(BASE, "randomization")}
    assert set(ranges) == set(DEFAULT_RANDOMIZATION)
    ixx = ranges["aerostat.Ixx"]
    np.testing.assert_allclose((ixx.low, ixx.high), (BASE.aerostat.Ixx * 0.7, BASE.aerostat.Ixx * 1.3))
    rows = {r["key"]: r for r in range_disagreements(BASE)}
    # hull cross-flow drag: documented 0.3-1.2, randomisation 1.2 * (1 -+ 0.2)
    np.testing.assert_allclose(rows["hull.Cdc"]["documented"], (0.3, 1.2))
    np.testing.assert_allclose(rows["hull.Cdc"]["randomization"], (0.96, 1.44))
    assert rows["aerostat.mass"]["documented"] is None
    assert "aerostat.Ixx" not in rows  # +-30 % in both
    with pytest.raises(ValueError, match="unknown range source 'paper'"):
        estimated_ranges(BASE, "paper")


def test_draws_are_uniform_in_their_ranges():
    ranges = estimated_ranges(BASE)
    n = 20_000
    x = draw_values(ranges, n, seed=3)
    lo, hi = np.array([r.low for r in ranges]), np.array([r.high for r in ranges])
    assert np.all(x >= lo) and np.all(x <= hi)
    # the mean of U(lo, hi) is the midpoint with standard error (hi - lo) / sqrt(12 n)
    z = (x.mean(axis=0) - (lo + hi) / 2) / ((hi - lo) / math.sqrt(12 * n))
    assert np.all(np.abs(z) < 4.0), z
    np.testing.assert_array_equal(x, draw_values(ranges, n, seed=3))
    for bad in (0, 10**9):  # above MAX_SAMPLES: refused before the arrays are allocated
        with pytest.raises(ValueError, match=r"--samples must be an integer in \[1, 1000000\]"):
            draw_values(ranges, bad, seed=0)


# --- the per-sample function ------------------------------------------------------------------------


def test_nominal_sample_reproduces_the_sensitivity_baseline():
    """At the nominal values the study's sample equals the sensitivity table's baseline (an
    independent loop over the same trims), and the Table 2 periods are the README's."""
    ranges = estimated_ranges(BASE)
    res = evaluate_sample(BASE, ranges, np.array([r.nominal for r in ranges]),
                          np.asarray(DAMPING_SPEEDS))
    ref = sensitivity_evaluate(BASE)
    assert res.error == ""
    np.testing.assert_allclose(res.periods, [ref[k] for k in PERIOD_KEYS], rtol=1e-9)
    np.testing.assert_allclose(res.periods, [44.897, 67.580, 2.9415, 1.7804], rtol=2e-4)
    assert np.nanmin(res.zeta) == pytest.approx(ref["min_zeta"], rel=1e-9)
    assert np.all(res.all_stable == 1.0) and ref["all_stable"]
    assert np.nanmax(res.max_real) == pytest.approx(ref["max_real"], rel=1e-9)


def test_a_set_that_cannot_fly_is_recorded_not_raised():
    heavy = ParameterRange("aerostat.mass", 900.0, 900.0, BASE.aerostat.mass,
                           lambda p, v: p.replace(**{"aerostat.mass": v}))
    res = evaluate_sample(BASE, [heavy], np.array([900.0]), np.array(FAST_SPEEDS))
    assert res.error.startswith("invalid parameter set"), res.error
    assert np.all(np.isnan(res.stable)) and np.all(np.isnan(res.periods))
    # a study draws aerostats that can exist: ranges that give none are refused, named
    with pytest.raises(ValueError, match=r"only 0 of 200 parameter sets drawn from the ranges "
                                         r"are valid \(first refusal: aerostat.mass = 900.0 kg "
                                         r"gives no net lift"):
        run_serial(BASE, [heavy], 2, seed=0, speeds=FAST_SPEEDS)


def test_summary_of_a_study_with_no_complete_sample():
    """Samples that stopped (here: recorded invalid) count as failed, never as stable."""
    heavy = ParameterRange("aerostat.mass", 900.0, 900.0, BASE.aerostat.mass,
                           lambda p, v: p.replace(**{"aerostat.mass": v}))
    failed = evaluate_sample(BASE, [heavy], np.array([900.0]), np.array(FAST_SPEEDS))
    study = Study(["aerostat.mass"], [(900.0, 900.0)], [BASE.aerostat.mass],
                  np.array(FAST_SPEEDS), 0, [failed, failed], "serial", 1.0)
    summary = summarize(study)
    assert (summary["n_errors"], summary["stable_everywhere"]["count"]) == (2, 0)
    assert summary["correlations"] == [] and summary["periods_s"][PERIOD_KEYS[0]] == {"n": 0}
    assert summary["rejected_draws"] == 0


def test_drawn_moments_are_checked_together_not_one_by_one():
    """Ixx = 2200, Iyy = 9700, Izz = 9000 kg m^2 is a body (9700 <= 2200 + 9000 and
    hypot(9000 - 2200, 2 * 300) = 6826 <= 9700), but Iyy = 9700 with the nominal Izz = 7103
    is not (9700 > 2200 + 7103): applied one by one the set would be refused half-drawn."""
    ranges = [r for r in estimated_ranges(BASE, "randomization")
              if r.key in ("aerostat.Ixx", "aerostat.Iyy", "aerostat.Izz")]
    assert [r.key for r in ranges] == ["aerostat.Ixx", "aerostat.Iyy", "aerostat.Izz"]
    p = sample_params(BASE, ranges, np.array([2200.0, 9700.0, 9000.0]))
    assert (p.aerostat.Ixx, p.aerostat.Iyy, p.aerostat.Izz) == (2200.0, 9700.0, 9000.0)
    with pytest.raises(ParameterError, match=r"aerostat.Iyy = 9700.0 kg m\^2 exceeds"):
        BASE.replace(**{"aerostat.Ixx": 2200.0}).replace(**{"aerostat.Iyy": 9700.0})


def test_draws_that_are_no_body_are_redrawn():
    """Ixx, Iyy, Izz drawn independently by +-30 % break a triangle inequality in about 10 %
    of draws (Iyy > Ixx + Izz, or |Izz - Ixx| > Iyy, closed form of the principal moments):
    those are redrawn, every kept set loads, the valid first draws keep their order, and the
    study's metadata and summary count the redraws."""
    ranges = estimated_ranges(BASE)
    n = 400
    raw = draw_values(ranges, n, seed=0)
    values, rejected = draw_valid(BASE, ranges, n, seed=0)
    keys = [r.key for r in ranges]
    ixx, iyy, izz, ixz = (raw[:, keys.index(f"aerostat.{k}")] for k in ("Ixx", "Iyy", "Izz", "Ixz"))
    physical = (iyy <= ixx + izz) & (np.hypot(ixx - izz, 2 * ixz) <= iyy)
    # 1000-draw estimate 10.5 %; at n = 400 the binomial 4-sigma band is 5.6-15.4 %
    assert 0.056 < 1 - physical.mean() < 0.154
    assert len(rejected) >= (~physical).sum() and "no mass distribution" in rejected[0]
    np.testing.assert_array_equal(values[:physical.sum()], raw[physical])
    assert values.shape == raw.shape
    for row in values[::40]:
        sample_params(BASE, ranges, row)  # every kept set loads
    expected = len(draw_valid(BASE, ranges, 6, seed=0)[1])
    study = run_serial(BASE, ranges, 6, seed=0, speeds=(10.0,))
    assert study.meta["rejected"] == expected == 1
    assert summarize(study)["rejected_draws"] == 1


# --- statistics ---------------------------------------------------------------------------------------


def test_wilson_interval_matches_scipy():
    for k, n in ((7, 10), (0, 10), (95, 100)):
        ref = stats.binomtest(k, n).proportion_ci(method="wilson")
        np.testing.assert_allclose(wilson_interval(k, n), (ref.low, ref.high), rtol=1e-9, atol=1e-12)
    # 0 of n: the upper bound is z^2 / (n + z^2)
    assert wilson_interval(0, 10)[1] == pytest.approx(1.959964**2 / (10 + 1.959964**2), rel=1e-6)


def test_point_biserial_matches_scipy_and_closed_form():
    x = np.linspace(0.0, 1.0, 101)
    y = (x < 0.3).astype(float)
    assert point_biserial(x, y) == pytest.approx(stats.pointbiserialr(y, x).statistic, rel=1e-12)
    # r_pb = (M1 - M0) / s_n * sqrt(p q), s_n the population standard deviation of x
    p = y.mean()
    closed = (x[y == 1].mean() - x[y == 0].mean()) / x.std() * math.sqrt(p * (1 - p))
    assert point_biserial(x, y) == pytest.approx(closed, rel=1e-12)
    assert math.isnan(point_biserial(x, np.zeros_like(x)))


def _synthetic_study(n: int = 10) -> Study:
    """n samples of one parameter x = 0 .. 1; the first mode is unstable at the first of two
    speeds exactly where x < 0.3 (3 of 10 samples)."""
    x = np.linspace(0.0, 1.0, n)
    samples = []
    for v in x:
        stable = np.ones((2, len(MODES)))
        stable[0, 0] = 0.0 if v < 0.3 else 1.0
        samples.append(SampleResult(np.array([v]), stable, np.full((2, len(MODES)), 0.1),
                                    np.full((2, len(MODES)), 10.0), stable.min(axis=1),
                                    np.array([0.01 if v < 0.3 else -0.01, -0.02]),
                                    np.arange(len(PERIOD_KEYS), dtype=float) + v))
    return Study(["x"], [(0.0, 1.0)], [0.5], np.array([1.0, 2.0]), 0, samples, "serial", 1.0)


def test_summary_of_a_known_study():
    st = _synthetic_study()
    assert stable_everywhere(st).sum() == 7
    rows = {(r["wind_speed_m_s"], r["mode"]): r for r in stability_table(st)}
    first = f"{MODES[0][0]} {MODES[0][1]}"
    assert rows[(1.0, first)]["p_stable"] == pytest.approx(0.7)
    assert rows[(2.0, first)]["p_stable"] == 1.0
    assert rows[(1.0, "all modes")]["p_stable"] == pytest.approx(0.7)
    corr = correlations(st)[0]
    x = np.linspace(0.0, 1.0, 10)
    assert corr["r_unstable"] == pytest.approx(np.corrcoef(x, x < 0.3)[0, 1], rel=1e-12)
    assert corr["rho_max_real"] == pytest.approx(stats.spearmanr(x, np.where(x < 0.3, 0.01, -0.01)).statistic)
    assert (corr["unstable_rate_low_fifth"], corr["unstable_rate_high_fifth"]) == (1.0, 0.0)
    s = summarize(st)
    assert s["stable_everywhere"]["fraction"] == pytest.approx(0.7)
    np.testing.assert_allclose(s["stable_everywhere"]["ci95"], wilson_interval(7, 10))
    assert s["periods_s"][PERIOD_KEYS[0]]["p50"] == pytest.approx(0.5)
    assert s["mode_instabilities"][0]["samples_unstable"] == 3
    assert s["mode_instabilities"][0]["speeds_m_s"] == [1.0]
    r = np.corrcoef(x, x < 0.3)[0, 1]  # every sweep complete: the line as it always read
    assert f"{first}: 3 sets, at 1 speeds in 1-1 m/s; follows x (r {r:+.2f})" in format_summary(s)


def _study_with_failed_sweeps():
    """Four sets on two speeds: the first mode unstable at 1 m/s in sets 0 and 1, whose trims
    fail at 2 m/s (nan there), stable in the two complete sets 2 and 3."""
    samples = []
    for k in range(4):
        stable = np.ones((2, len(MODES)))
        if k < 2:
            stable[0, 0], stable[1] = 0.0, np.nan
        samples.append(SampleResult(np.array([0.1 * k]), stable, np.full((2, len(MODES)), 0.1),
                                    np.full((2, len(MODES)), 10.0), stable.min(axis=1),
                                    np.array([0.01 if k < 2 else -0.01, -0.02]),
                                    np.zeros(len(PERIOD_KEYS)),
                                    "trim failed: no equilibrium" if k < 2 else ""))
    return Study(["x"], [(0.0, 1.0)], [0.5], np.array([1.0, 2.0]), 0, samples, "serial", 1.0)


def test_mode_instabilities_count_as_the_probability_table_does():
    """Two of four sets are unstable in the first mode at 1 m/s and then fail to trim: the
    probability table gives P(stable) = 2/4 there, and the mode's summary counts the same 2
    sets (it counted only the complete sweeps, 0); its correlation, over the 2
    complete sweeps that are both stable, is undefined, which the text says instead of
    printing "follows None (r +nan)"."""
    s = summarize(_study_with_failed_sweeps())
    first = f"{MODES[0][0]} {MODES[0][1]}"
    row = next(r for r in s["stability"] if r["mode"] == first and r["wind_speed_m_s"] == 1.0)
    assert (row["n"], row["p_stable"]) == (4, 0.5)
    m = s["mode_instabilities"][0]
    assert (m["samples_unstable"], m["complete"], m["complete_unstable"]) == (2, 2, 0)
    assert m["speeds_m_s"] == [1.0] and m["top_parameter"] is None and math.isnan(m["r"])
    assert m["no_r"] == "0 of the 2 complete sweeps are unstable in it (r needs both outcomes)"
    text = format_summary(s)
    assert f"unstable {first}: 2 of 4 sets (failed sweeps counted up to where they failed)" in text
    assert "None" not in text and "nan" not in text
    assert "no parameter named: 0 of the 2 complete sweeps are unstable in it" in text


# --- serial and Ray paths ---------------------------------------------------------------------------------


def test_ray_monte_carlo_is_identical_to_serial(ray_session):
    ranges = estimated_ranges(BASE)
    serial = run_serial(BASE, ranges, 4, seed=11, speeds=FAST_SPEEDS)
    remote = run_ray(BASE, ranges, 4, seed=11, speeds=FAST_SPEEDS, batch_size=2)
    assert remote.meta["batches"] == 2 and remote.backend == "ray"
    assert studies_identical(serial, remote)
    # and each equals the per-sample function called directly
    direct = evaluate_sample(BASE, ranges, draw_valid(BASE, ranges, 4, 11)[0][3],
                             np.array(FAST_SPEEDS))
    np.testing.assert_array_equal(remote.samples[3].periods, direct.periods)
    assert np.all(np.isfinite(serial.stack("periods")))


def test_throughput_command_prints_rates(ray_session, capsys):
    rc = main(["montecarlo", "--bench", "--samples", "2", "--wind", "1:2:1", "--repeats", "2",
               "--json"])
    res = json.loads(capsys.readouterr().out)
    assert rc == 0 and res["identical_to_serial"] is True
    for key in ("serial_sets_per_s", "ray_warm_sets_per_s"):
        r = res[key]
        assert len(r["runs"]) == 2 and r["median"] == pytest.approx(np.median(r["runs"]))
    assert res["ray_init_s"] == 0.0  # the session's instance is reused, not started again


def test_montecarlo_command_writes_its_outputs(tmp_path, capsys):
    out = tmp_path / "mc"
    rc = main(["montecarlo", "--samples", "3", "--seed", "5", "--serial", "--wind", "1:2:1",
               "--out", str(out)])
    assert rc == 0
    summary = json.loads((out / "summary.json").read_text())
    with (out / "samples.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert summary["samples"] == 3 and len(rows) == 3
    assert summary["stable_everywhere"]["count"] == sum(int(r["stable_everywhere"]) for r in rows)
    direct = evaluate_sample(BASE, estimated_ranges(BASE), draw_valid(BASE, estimated_ranges(BASE), 3, 5)[0][0],
                             np.array([1.0, 2.0]))
    assert float(rows[0]["long_pendulum_s"]) == pytest.approx(direct.periods[0], rel=1e-12)
    assert (out / "montecarlo.png").stat().st_size > 10_000
    text = capsys.readouterr().out
    assert "Monte Carlo on baseline: 3 parameter sets" in text
    assert "stable at every wind speed" in text


# --- missing extra ---------------------------------------------------------------------------------------


def _space_file(tmp_path):
    path = tmp_path / "space.yml"
    path.write_text("TetheredAerostatDamping-v0:\n"
                    "  learning_rate: {loguniform: [1.0e-4, 1.0e-3]}\n")
    return path


@pytest.mark.parametrize("argv", [["montecarlo", "--samples", "2"], ["tune", "--space", "SPACE"]])
def test_without_the_extra_commands_exit_2_with_one_line(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ImportError
    argv = [str(_space_file(tmp_path)) if a == "SPACE" else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"aerostat-gym {argv[0]}: error: ")
    assert "needs the optional 'ray' extra" in err[0] and 'pip install "aerostat-gym[ray]"' in err[0]


@pytest.mark.parametrize("argv, module, extra", [
    (["evaluate", "--policy", "passive", "--out", "OUT"], "matplotlib", "plot"),
    (["demo", "--out", "OUT"], "matplotlib", "plot"),
    (["stability", "--wind", "5", "--plot", "OUT"], "matplotlib", "plot"),
    (["wind", "--duration", "10", "--plot", "OUT/w.png"], "matplotlib", "plot"),
    (["montecarlo", "--samples", "2", "--serial", "--out", "OUT"], "matplotlib", "plot"),
    (["evaluate", "--policy", "shipped", "--no-plots", "--out", "OUT"], "stable_baselines3",
     "train"),
])
def test_a_missing_extra_is_named_before_the_work(argv, module, extra, tmp_path, monkeypatch,
                                                   capsys):
    """A base install (no extras): each command that writes figures or loads a learned policy
    names the extra to install in one line, exit status 2, before any work (no episode run,
    nothing written), where it used to run its episodes and then fail with a traceback."""
    monkeypatch.setitem(sys.modules, module, None)  # import -> ImportError
    out = tmp_path / "out"
    argv = [a.replace("OUT", str(out)) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"aerostat-gym {argv[0]}: error: ")
    assert f"needs the optional '{extra}' extra" in err[0]
    assert f'pip install "aerostat-gym[{extra}]"' in err[0]
    assert not out.exists()


def test_unreachable_cluster_is_one_line_exit_2(monkeypatch, capsys):
    class FakeRay:  # stands in for ray: no session, and the cluster refuses the connection
        @staticmethod
        def is_initialized():
            return False

        @staticmethod
        def init(**kwargs):
            raise ConnectionError(f"Failed to connect to Ray cluster at {kwargs['address']}")

    monkeypatch.setitem(sys.modules, "ray", FakeRay)
    assert main(["montecarlo", "--samples", "2", "--address", "10.0.0.9:6379"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "could not join the Ray cluster at --address 10.0.0.9:6379" in err[0]


def test_serial_path_runs_without_ray(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)
    assert main(["montecarlo", "--samples", "1", "--serial", "--wind", "10", "--no-plot",
                 "--set", "tether.length=150", "--out", str(tmp_path / "mc")]) == 0
    summary = json.loads((tmp_path / "mc" / "summary.json").read_text())
    assert summary["samples"] == 1 and summary["correlations"] == []  # one set: nothing to correlate
    assert summary["meta"]["configuration"] == "baseline --set tether.length=150"
    with pytest.raises(MissingExtraError, match="'ray' extra"):
        require("ray", "x", "ray")


# --- tune ----------------------------------------------------------------------------------------------


def test_search_space_parsing(tmp_path):
    path = tmp_path / "space.yml"
    path.write_text("TetheredAerostat-v0:\n"
                    "  learning_rate: {loguniform: [1.0e-4, 1.0e-3]}\n"
                    "  policy_kwargs.net_arch: {choice: [[64, 64], [128]]}\n"
                    "  n_steps: 64\n")
    space = load_space(path, "TetheredAerostat-v0")
    hp = apply_sample({"n_steps": 256, "policy_kwargs": {"log_std_init": -2.0}}, space,
                      {"learning_rate": 5e-4, "policy_kwargs.net_arch": "[128]", "seed": 1},
                      decode={"policy_kwargs.net_arch"})
    assert hp == {"n_steps": 64, "learning_rate": 5e-4,
                  "policy_kwargs": {"log_std_init": -2.0, "net_arch": [128]}}
    path.write_text("TetheredAerostat-v0:\n  gamma: {uniform: [0.99, 0.9]}\n")
    with pytest.raises(TuneSpaceError, match="'gamma' uniform needs"):
        load_space(path, "TetheredAerostat-v0")


def test_a_whole_quniform_grid_samples_integers(tmp_path):
    """quniform over whole numbers (a count such as n_steps, which the training refuses as a
    float) samples integers on the grid, both ends included; a fractional grid stays float."""
    from ray import tune

    path = tmp_path / "space.yml"
    path.write_text("TetheredAerostat-v0:\n  n_steps: {quniform: [64, 256, 64]}\n"
                    "  gamma: {quniform: [0.9, 0.99, 0.01]}\n")
    space, _ = tune_space(load_space(path, "TetheredAerostat-v0"), tune)
    rng = np.random.default_rng(0)
    draws = [space["n_steps"].sample(random_state=rng) for _ in range(200)]
    assert all(isinstance(v, (int, np.integer)) for v in draws)
    assert set(int(v) for v in draws) == {64, 128, 192, 256}
    assert isinstance(space["gamma"].sample(random_state=rng), float)


def test_config_table_mean_and_bootstrap_ci():
    trials = [{"config": "a", "seed": s, "final_score": v, "best_score": v + 1}
              for s, v in enumerate([1.0, 2.0, 3.0])]
    trials.append({"config": "b", "seed": 0, "final_score": 5.0, "best_score": 5.0})
    table = config_table(trials)
    assert [r["config"] for r in table] == ["b", "a"]
    a = table[1]
    assert a["final_score_mean"] == 2.0 and a["best_score_mean"] == 3.0 and a["n_seeds"] == 3
    assert 1.0 <= a["final_score_ci95_low"] < 2.0 < a["final_score_ci95_high"] <= 3.0
    assert (table[0]["final_score_ci95_low"], table[0]["final_score_ci95_high"]) == (5.0, 5.0)


TINY_PPO = """TetheredAerostatDamping-v0:
  n_timesteps: 128
  n_envs: 2
  policy: MlpPolicy
  normalize: "dict(norm_obs=True, norm_reward=True)"
  gamma: 0.99
  n_steps: 64
  batch_size: 64
  n_epochs: 1
  policy_kwargs: {log_std_init: -2.0, net_arch: {pi: [16], vf: [16]}}
aerostat_gym:
  eval_freq: 128
  eval_suite: damping
"""


def test_tune_two_trials_write_the_table(ray_session, tmp_path, capsys):
    """Two trials (one configuration, seeds 0 and 1) through Ray Tune with a tiny budget."""
    base = tmp_path / "ppo_tiny.yml"
    base.write_text(TINY_PPO)
    out = tmp_path / "tune"
    rc = main(["tune", "--algo", "ppo", "--hyperparams", str(base), "--space", str(_space_file(tmp_path)),
               "--seeds", "0", "1", "--configs", "1", "--searcher", "optuna", "--scheduler", "asha",
               "--out", str(out),
               "--threads", "1"])
    assert rc == 0, capsys.readouterr()
    with (out / "trials.csv").open() as fh:
        trials = list(csv.DictReader(fh))
    assert len(trials) == 2 and sorted(int(t["seed"]) for t in trials) == [0, 1]
    assert len({t["config"] for t in trials}) == 1 and not any(t["error"] for t in trials)
    for t in trials:  # the score Tune saw is the one the training function wrote
        evals = json.loads((tmp_path / t["trial_dir"] / "run" / "evaluations.json").read_text())
        assert float(t["final_score"]) == pytest.approx(evals[-1]["score"], rel=1e-12)
        assert int(t["timesteps"]) == evals[-1]["timesteps"] == 128
    res = json.loads((out / "tune_results.json").read_text())
    row = res["table"][0]
    assert row["n_seeds"] == 2
    assert row["final_score_mean"] == pytest.approx(np.mean([float(t["final_score"]) for t in trials]))
    assert (out / "best" / "best_model.zip").is_file()
    assert (out / "best" / "best_model_vecnormalize.pkl").is_file()
    # the copied checkpoint with its VecNormalize statistics scores what Tune recorded for it
    rescored = evaluate_policy(str(out / "best" / "best_model.zip"), "damping")["score"]
    assert rescored == pytest.approx(res["best"]["best_score"], rel=1e-9)
    task, best_hp, project = load_hyperparams("ppo", out / "best" / "hyperparams.yml")
    assert task == "TetheredAerostatDamping-v0" and project["eval_suite"] == "damping"
    assert best_hp["learning_rate"] == json.loads(trials[0]["config"])["learning_rate"]
    assert best_hp["n_timesteps"] == 128 and best_hp["n_steps"] == 64


def test_the_shipped_search_space_fits_the_shipped_base_file():
    """``tune --algo ppo`` without --space reads the shipped space, keyed by the task of the
    shipped ppo.yml (it was keyed by the 0.3 base's task and refused); an algorithm with no
    shipped space is named."""
    from aerostat_gym.cli import build_parser
    from aerostat_gym.cli.scale import setup_from_args

    setup = setup_from_args(build_parser().parse_args(["tune", "--algo", "ppo"]))
    assert setup.task == load_hyperparams("ppo")[0] == "TetheredAerostatRealistic-v0"
    assert setup.space["gamma"] == {"uniform": [0.98, 0.998]}
    with pytest.raises(ValueError, match="no search space ships for sac; pass --space"):
        setup_from_args(build_parser().parse_args(["tune", "--algo", "sac"]))
