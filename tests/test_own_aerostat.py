"""Your own aerostat (issue 15): every command, figure and controller follows the parameter file.

Parametrised over the shipped configurations and generated aerostats (aerostat_gym.scaling:
different volume, tether length, element count and trim pitch), each written to a TOML file and
passed with ``--config``. Checks, with their tolerances:

- zero-wind tensions: top = B - m g, winch = B - m g - mu L g (rel 1e-6);
- Table 2 theory columns = independent closed forms, massless and with the tether's mass
  (rel 1e-9), and every linear period within the band of the README ("Your own aerostat") of
  its own tether-mass closed form, on far-from-baseline aerostats too;
- the paper's columns only for the paper's case, and no baseline number in other outputs;
- Figure 8 run on the configured length; every mode stable over the sweep;
- an LQR whose nonlinear closed-loop pendulum damping matches its linear prediction (rel 20 %);
- environment episodes on the configured parameters without failure.

The default suite runs the shipped aerostats and two generated ones with short sweeps; the
``slow`` test runs the full 0..20 m/s sweeps, the Figure 8 script and the agent commands.
"""

import json
import math
import warnings
from collections import Counter

import gymnasium as gym
import numpy as np
import pytest

from aerostat_gym.agents.evaluate import default_wind_range, evaluate_policy, held_suite_speeds
from aerostat_gym.agents.lqr import (
    LQR_MAX_DEVIATIONS,
    LQRPolicy,
    LQRSchedule,
    mode_initial_state,
    scaled_deviations,
)
from aerostat_gym.agents.metrics import fit_damped_sinusoid
from aerostat_gym.agents.policies import load_policy
from aerostat_gym.agents.privileged import set_point_law
from aerostat_gym.agents.train import held_training_winds
from aerostat_gym.analysis.figures import family_values, figure8_data
from aerostat_gym.analysis.linear import ACTUATORS, U_FREE, input_jacobian
from aerostat_gym.analysis.modes import analyse, wind_sweep
from aerostat_gym.analysis.reference import (
    THEORY_TOLERANCE_PCT,
    closed_form_periods,
    format_table2,
    table2,
    veering_allowance,
)
from aerostat_gym.analysis.sensitivity import (
    default_knobs,
    format_sensitivity,
    select_knobs,
    sensitivity_table,
)
from aerostat_gym.analysis.trim import TrimError, find_equilibrium
from aerostat_gym.bench.soak import VARIANTS, soak_configuration
from aerostat_gym.cli import main
from aerostat_gym.cli.agents import demo_summary
from aerostat_gym.cli.stability import trimmed_speeds
from aerostat_gym.envs.batch import held_wind_top
from aerostat_gym.envs.config import PERTURBATIONS, TaskConfig, TaskError
from aerostat_gym.envs.episodes import TrimTable
from aerostat_gym.envs.reward import DEFAULT_WEIGHTS, reward_table
from aerostat_gym.envs.spaces import (
    OBS_DX,
    OBS_DY,
    OBS_VX,
    OBS_VY,
    REFERENCE_TETHER_LENGTH,
    displacement_scale,
)
from aerostat_gym.params import (
    SEMI_IMPLICIT_REFERENCE_DT,
    SEMI_IMPLICIT_REFERENCE_HULL_LENGTH,
    ParameterError,
    ParameterWarning,
    advised_semi_implicit_dt,
    dumps_toml,
    load_params,
    paid_out_weight,
    parameter_table,
    params_from_dict,
    tether_drag_step,
)
from aerostat_gym.params.files import tomllib
from aerostat_gym.registration import ENV_ID
from aerostat_gym.scaling import scale_aerostat
from aerostat_gym.sim import Model, simulate
from aerostat_gym.wind.sizing import configured_wind, highest_point, sized_turbulence

#: Generated aerostats: (volume factor, tether length [m], elements, trim pitch [deg]).
GENERATED = {"gen_small": (0.4, 200.0, 6, -2.0), "gen_large": (3.0, 500.0, 8, -6.0)}
SHIPPED = ("aeros_flightcam", "tcom_32m")
CASES = SHIPPED + tuple(GENERATED)
#: [LN02]'s printed numbers (Table 2) and the baseline's length and mass, which must not appear
#: in the outputs of any other configuration.
BASELINE_TOKENS = ("L = 300 m", "325.7", "43.90s", "58.00s", "67.40s", "44.40s", "paper")


def _params(name):
    if name in SHIPPED:
        return load_params(name)
    return scale_aerostat(load_params(), *GENERATED[name])


@pytest.fixture(scope="module", params=CASES)
def case(request, tmp_path_factory):
    """(name, Params, --config argument): shipped ones by name, generated ones as a file."""
    name = request.param
    p = _params(name)
    if name in SHIPPED:
        return name, p, name
    path = tmp_path_factory.mktemp(name) / f"{name}.toml"
    path.write_text(dumps_toml(p))
    return name, p, str(path)


def _run(capsys, argv):
    capsys.readouterr()
    assert main(argv) == 0, argv
    return capsys.readouterr().out


def _no_baseline_numbers(name, text):
    if name == "aeros_flightcam":
        return
    for token in BASELINE_TOKENS:
        assert token not in text, (name, token)


def test_zero_wind_tensions(case, capsys):
    """trim --wind 0: top tension B - m g, winch tension B - m g - mu L g (rel 1e-6)."""
    name, p, cfg = case
    s = json.loads(_run(capsys, ["trim", "--config", cfg, "--wind", "0", "--json"]))
    d = p.derived
    net = p.environment.rho_air * p.environment.g * p.aerostat.volume - p.aerostat.mass * p.environment.g
    assert s["top_tension_N"] == pytest.approx(net, rel=1e-6)
    assert s["winch_tension_N"] == pytest.approx(net - d.mass_per_length * p.tether.length
                                                 * p.environment.g, rel=1e-6)
    _no_baseline_numbers(name, _run(capsys, ["trim", "--config", cfg, "--wind", "0"]))


def _closed_forms(p):
    """[LN02]'s massless point-mass closed forms, written out here (not taken from the
    package)."""
    rho, g, a, t = p.environment.rho_air, p.environment.g, p.aerostat, p.tether
    net = rho * g * a.volume - a.mass * g
    mex, mey, mez = (a.mass + k * rho * a.volume for k in (a.k1, a.k3, a.k3))
    area = math.pi * t.diameter ** 2 / 4
    L, mu = t.length, t.density * area
    return {"long_pendulum": 2 * math.pi * math.sqrt(mex * L / net),
            "lat_pendulum": 2 * math.pi * math.sqrt(mey * L / net),
            "axial_spring": 2 * math.pi * math.sqrt(mez * L / (t.youngs_modulus * area)),
            "tether_1st": 2 * L / math.sqrt(net / mu)}


def test_table2_against_own_closed_forms(case, capsys):
    """table2 --config: the theory column is this aerostat's point-mass closed form (rel
    1e-9); the linear model in still air lies in its README band of the aerostat's still-air
    closed form (pendulums 2 %, axial 3 %, tether 10 %); the paper's columns appear only for
    the paper's case."""
    name, p, cfg = case
    rows = json.loads(_run(capsys, ["table2", "--config", cfg, "--json"]))
    ref = _closed_forms(p)
    assert THEORY_TOLERANCE_PCT == {"long_pendulum": 2.0, "lat_pendulum": 2.0,
                                    "axial_spring": 3.0, "tether_1st": 10.0}
    for r in rows:
        assert r["theory_s"] == pytest.approx(ref[r["key"]], rel=1e-9), (name, r)
        assert abs(r["calm_linear_s"] / r["closed_form_s"] - 1) * 100 <= THEORY_TOLERANCE_PCT[r["key"]], (name, r)
        assert r["within_tolerance"], (name, r)
        assert ("paper_linear_s" in r) == (name == "aeros_flightcam"), (name, r)
    text = _run(capsys, ["table2", "--config", cfg])
    assert "MISS" not in text
    _no_baseline_numbers(name, text)


def test_table2_reads_an_overdamped_mode_as_real_like_stability(capsys):
    """0.003x the baseline on 1053 m trimmed 12 deg nose down: at 1 m/s the longitudinal
    pendulum and the first harmonic are real eigenvalues (stability: 'real (1.000)'); table2
    says 'real' with n/a differences (it printed 2 pi / |lambda|, 225 s and 1.02 s, as
    periods), and its still-air column still matches the closed form."""
    p = scale_aerostat(load_params(), 0.003, 1053.0, 29, 12.0)
    rows = {r["key"]: r for r in table2(p)}
    sweep = analyse(p, find_equilibrium(p, 1.0))
    for key in ("long_pendulum", "tether_1st"):
        assert rows[key]["linear_overdamped"] and math.isnan(rows[key]["linear_s"])
        assert math.isnan(rows[key]["diff_pct"]) and rows[key]["within_tolerance"]
    assert not sweep.find("long", "pendulum").oscillatory
    assert rows["axial_spring"]["linear_s"] == pytest.approx(
        sweep.find("long", "axial spring").period, rel=1e-12)
    line = [s for s in format_table2(list(rows.values())).splitlines()
            if s.startswith("Long. pendulum")][0]
    assert line.split("|")[1].split()[1:] == ["real", "n/a", "n/a"]


def test_table2_under_a_sheared_wind_is_not_the_papers_case():
    """[LN02]'s wind is uniform: the baseline aerostat under a power-law profile gets no paper
    columns (its 'U = 1' is not 1 m/s at the aerostat, and the paper's band would read MISS),
    and its still-air rows (0.02 m/s, where the shear barely acts) are the uniform case's within
    0.01 % (measured: 2e-5 in the lateral pendulum, whose yaw coupling feels the shear)."""
    sheared = load_params().replace(**{"wind.profile": "power"})
    rows, uniform = table2(sheared), {r["key"]: r for r in table2(load_params())}
    for r in rows:
        assert "paper_linear_s" not in r and "within_paper_band" not in r
        assert "paper_linear_s" in uniform[r["key"]]
        assert r["calm_linear_s"] == pytest.approx(uniform[r["key"]]["calm_linear_s"], rel=1e-4)


@pytest.mark.parametrize("factor, length, n, pitch, key, point_pct, calm_pct, wind_pct", [
    (100.0, 2000.0, 16, None, "long_pendulum", 8.13, -0.06, -0.07),
    (0.01, 40.0, 6, None, "lat_pendulum", 36.32, 0.12, 32.58),
    (0.726, 40.0, 12, 1.3, "long_pendulum", 11.31, 0.10, 0.08),
    (0.412, 1348.0, 7, -9.5, "lat_pendulum", 51.58, -0.02, 45.67)])
def test_table2_on_extreme_aerostats(factor, length, n, pitch, key, point_pct, calm_pct, wind_pct):
    """Far from the baseline every row passes in still air, where the point-mass theory would
    not. 100x on 2000 m (the tether weighs 18 % of the net lift): the linear pendulum is 8.1 %
    off the massless point mass, -0.06 % off the closed form. A 0.73x hull on 40 m: the hull
    turns with the swing, +11.3 % off the point mass, +0.10 % off the rigid hull's closed form.
    0.01x on 40 m and 0.41x on 1348 m trimmed 9.5 deg nose up: the lateral pendulum is
    yaw-coupled at 1 m/s (+32.6 % and +45.7 % over the closed form, reported, not judged) and
    within 0.12 % of it in still air. Differences within 0.2 points of these measurements."""
    rows = {r["key"]: r for r in table2(scale_aerostat(load_params(), factor, length, n, pitch))}
    assert all(r["within_tolerance"] for r in rows.values()), rows
    assert rows[key]["diff_pct"] == pytest.approx(point_pct, abs=0.2), rows[key]
    assert rows[key]["calm_diff_pct"] == pytest.approx(calm_pct, abs=0.2), rows[key]
    assert rows[key]["wind_effect_pct"] == pytest.approx(wind_pct, abs=0.2), rows[key]


@pytest.mark.parametrize("pitch", [-10.0, 0.0, 10.0])
def test_axial_spring_across_trim_pitch(pitch):
    """The baseline re-trimmed from -10 to +10 deg: the axial spring in still air within 0.3 %
    of the closed form, which turns the hull with the tether's spring (the point-mass form was
    6.5 % off at +10 deg). At +10 deg the axial spring and the pitching share one motion
    (about half stretch, half pitch in each) and the two models name the pair the other way
    round: the row is judged against the closed form's pitching (3.088 s against 3.094 s). A
    closed form outside the linear pair gets no veering allowance."""
    p = scale_aerostat(load_params(), 1.0, 300.0, trim_pitch_deg=pitch)
    row = {r["key"]: r for r in table2(p)}["axial_spring"]
    assert row["within_tolerance"] and "veers_with" not in row, row
    assert abs(row["calm_diff_pct"]) <= 0.3, row
    assert row["closed_form_mode"] == ("pitching" if pitch == 10.0 else "axial_spring"), row
    analysis = analyse(p, find_equilibrium(p, 0.02))
    axial = analysis.find("long", "axial spring").period
    outside = 0.5 * min(axial, analysis.find("long", "pitching").period)
    assert veering_allowance("axial_spring", outside, axial, -50.0, analysis) == {}


def test_axial_spring_veers_where_the_tether_harmonic_comes_near():
    """9.65x the baseline on 708 m trimmed +7.3 deg: the first tether harmonic (closed form
    4.31 s) comes near the axial spring (4.67 s), which the closed form's straight tether leaves
    out; the linear axial spring, 4.38 % shorter, lies across the closed form from the mode it
    veers with (4.463 < 4.668 < 4.903 s: 48 % tether, 36 % pitch, so named the first tether
    harmonic, the pitching being the 3.78 s mode with 59 % pitch), so the row passes on the
    veering band (10 %)."""
    p = scale_aerostat(load_params(), 9.651, 708.0, 8, 7.3)
    row = {r["key"]: r for r in table2(p)}["axial_spring"]
    assert row["veers_with"] == "tether 1st harmonic" and row["tolerance_pct"] == 10.0, row
    assert row["veering_partner_s"] == pytest.approx(4.903, abs=0.002), row
    assert row["within_tolerance"], row
    assert row["calm_diff_pct"] == pytest.approx(-4.38, abs=0.1), row
    assert row["calm_linear_s"] < row["closed_form_s"] < row["veering_partner_s"], row


def test_table2_on_a_one_element_tether():
    """One element has no moving tether node: the modes still classify (a shape with no node
    has no sign change), the aerostat's rows pass (pendulum -0.15 % of the closed form), and the
    tether harmonic, which the model cannot carry, is a MISS that reads 'not found'."""
    p = load_params(overrides={"tether.n_elements": 1})
    rows = {r["key"]: r for r in table2(p)}
    assert rows["long_pendulum"]["calm_diff_pct"] == pytest.approx(-0.15, abs=0.05)
    assert all(rows[k]["within_tolerance"] for k in ("long_pendulum", "lat_pendulum", "axial_spring"))
    assert math.isnan(rows["tether_1st"]["calm_linear_s"]) and not rows["tether_1st"]["within_tolerance"]
    assert "not found" in format_table2(list(rows.values()))


def test_evaluate_on_a_tether_that_cannot_hold_the_default_winds(capsys, tmp_path):
    """A tether rated 3.3 kN holds the baseline's trims up to 11.9 m/s (largest tension 3.29 kN
    there, 3.30 kN at 12 m/s): the default wind range's top comes down to the highest 0.1 m/s grid
    speed it holds, ``evaluate`` on a suite that flies at 15 m/s is refused with the way out
    named, and ``--speeds 5 8`` runs on the winds the aerostat holds."""
    weak = ["--set", "tether.strength=3300", "--set", "winch.safe_working_load=3000"]
    p = load_params(overrides={"tether.strength": 3300.0, "winch.safe_working_load": 3000.0})
    lo, top = default_wind_range(p)
    trims = TrimTable(p, 3.0, 15.0)
    k = int(np.argmin(np.abs(trims.speeds - top)))
    assert lo == 3.0 and top == 11.9
    assert trims.largest_tensions[k] < 3300.0 <= trims.largest_tensions[k + 1]
    assert default_wind_range(load_params()) == (3.0, 15.0)
    assert main(["evaluate", "--policy", "passive", "--no-plots", "--out", str(tmp_path), *weak]) == 2
    assert "run its scenarios at wind speeds this aerostat holds with --speeds" in capsys.readouterr().err
    out = _run(capsys, ["evaluate", "--policy", "passive", "--speeds", "5", "8", "--no-plots",
                        "--out", str(tmp_path), "--json", *weak])
    rows = json.loads(out)[0]["scenarios"]["recover"]["episodes"]
    assert sorted(r["wind_speed"] for r in rows) == [5.0, 8.0]


def test_the_tether_holds_a_trim_by_its_largest_tension():
    """One rule decides where the tether breaks at trim: its largest tension, at the top end.
    A tether rated between the baseline's two end tensions at 15 m/s (3858 N at the confluence
    point, 3791 N at the winch: the tether's weight between) cannot hold that trim. The
    environment refuses 15 m/s (it used to judge the winch end, accept it and break on the first
    step), and its highest held wind is the stability sweep's, 14.8 m/s; there a calm episode
    does not break."""
    summary = find_equilibrium(load_params(), 15.0).summary
    top, winch = summary["top_tension_N"], summary["winch_tension_N"]
    assert top - winch == pytest.approx(67.3, abs=0.5)
    rating = 0.5 * (top + winch)
    p = load_params(overrides={"tether.strength": rating, "winch.safe_working_load": 0.9 * rating,
                               "winch.max_motor_force": 0.8 * rating})
    quiet = {"params": p, "turbulence": "none", "perturbation": "none"}
    with pytest.raises(TaskError, match=r"the trim at 15\.0 m/s loads the tether with 3858 N"):
        gym.make(ENV_ID, wind_speed=15.0, **quiet)
    swept = trimmed_speeds(p, np.round(np.arange(3.0, 15.05, 0.1), 1))[0]
    assert held_wind_top(p, 3.0, 15.0) == swept[-1] == 14.8
    with pytest.warns(UserWarning, match="winch.max_motor_force"):
        env = gym.make(ENV_ID, wind_speed=14.8, **quiet)
    env.reset(seed=0)
    for _ in range(25):
        _, _, terminated, _, info = env.step(np.zeros(1, np.float32))
        assert not terminated and info["peak_tension"] < rating


def test_training_on_a_tether_that_cannot_hold_the_task_winds():
    """Training on the 3.3 kN tether (holds the trims up to 11.9 m/s): the task's (3, 15) m/s
    comes down to the highest held wind with a warning that says so, and the evaluation suite
    runs its scenarios at the suite's speeds the tether holds (tiny: 5 and 10 m/s of 5, 10,
    15); on the baseline both stay as they are, without a warning."""
    weak = load_params(overrides={"tether.strength": 3300.0, "winch.safe_working_load": 3000.0})
    with pytest.warns(UserWarning, match=r"holds the trim only up to 11\.9 m/s; training on"):
        lo, top = held_training_winds({"params": weak, "wind_speed": (3.0, 15.0)})
    assert (lo, top) == default_wind_range(weak)
    assert held_suite_speeds("tiny", weak) == [5.0, 10.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert held_training_winds({"params": load_params()}) == (3.0, 15.0)
        assert held_suite_speeds("tiny", load_params()) is None


def test_family_sweep_ends_where_a_member_has_no_trim():
    """A 0.003x aerostat on 1053 m trimmed 15.5 deg nose up has no trim the solver finds from
    about 14.4 m/s (it is blown down on a tether that breaks at about 17 m/s): wind_sweep
    raises TrimError there, and with stop_without_trim (the Figure 9 families) it ends at the
    last speed that trims, 14 m/s of 0-20, all 15 analyses kept."""
    p = scale_aerostat(load_params(), 0.003, 1053.0, 6, -15.5)
    speeds = np.arange(0.0, 21.0, 1.0)
    with pytest.raises(TrimError, match="no equilibrium found at U = 14"):
        wind_sweep(p, speeds)
    sweep = wind_sweep(p, speeds, stop_without_trim=True)
    assert sweep.values.tolist() == speeds[:15].tolist() and len(sweep.analyses) == 15
    assert "no equilibrium found at U = 14" in str(sweep.stop_error)


@pytest.fixture(scope="module")
def fins_forward(tmp_path_factory):
    """The baseline with its fins' centres of pressure mirrored ahead of the CM (x = +5.715 m):
    directionally unstable, and with no trim the solver finds from 16.156 m/s."""
    data = tomllib.loads(dumps_toml(load_params()))
    for panel in data["fins"]["panels"]:
        panel["cp_position"][0] = -panel["cp_position"][0]
    path = tmp_path_factory.mktemp("finsfwd") / "finsfwd.toml"
    path.write_text(dumps_toml(params_from_dict(data)))
    return path


def test_stability_sweep_stops_where_the_trim_fails(capsys, fins_forward):
    """Fins ahead of the CM: ``stability --wind 1:21:5`` has no trim at 21 m/s (the continuation
    stalls at 16.156 m/s); it reports the speeds that trim, 1-16 m/s, with the divergent yaw
    (lambda = +1.388 1/s at 16 m/s, +1.155 at 11 m/s: a real root, Re > 0), warns where and
    why it stopped, and puts the stop into --json (it used to print only the trim error and
    exit 2). With no speed that trims the trim error stays."""
    capsys.readouterr()
    assert main(["stability", "--config", str(fins_forward), "--wind", "1:21:5", "--json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert sorted({row["wind_speed_m_s"] for row in out["modes"]}) == [1.0, 6.0, 11.0, 16.0]
    stop = out["stop"]
    assert (stop["last_wind_speed_m_s"], stop["failed_wind_speed_m_s"]) == (16.0, 21.0)
    assert stop["reason"].startswith("no trim at 21 m/s: no equilibrium found at U = 16.156 m/s")
    assert "the sweep stops at 16 m/s: no trim at 21 m/s" in captured.err
    assert out["all_stable"] is False
    yaw = next(u for u in out["unstable_modes"] if u["set"] == "lat" and u["label"] == "yaw")
    assert yaw["wind_speeds_m_s"] == [1.0, 6.0, 11.0, 16.0] and yaw["eigenvalue_im"] == 0.0
    assert yaw["worst_wind_speed_m_s"] == 16.0
    assert yaw["eigenvalue_re"] == pytest.approx(1.388, abs=0.005)
    text = _run(capsys, ["stability", "--config", str(fins_forward), "--wind", "11:21:10"])
    assert "UNSTABLE lateral yaw at U = 11 m/s; fastest at 11 m/s: lambda = +1.155 1/s" in text
    assert text.rstrip().splitlines()[-1].startswith("the sweep stops at 11 m/s: no trim at 21")
    assert main(["stability", "--config", str(fins_forward), "--wind", "17:20:1"]) == 2
    assert "error: no equilibrium found at U = 16.156 m/s" in capsys.readouterr().err


def test_demo_summary_names_every_unstable_mode(fins_forward):
    """At 10 m/s with the fins ahead of the CM the five listed modes are all damped; the
    summary's "all modes stable = False" is the divergent yaw, now listed with lambda =
    +1.075 1/s and the time its amplitude takes to double, ln 2 / lambda = 0.645 s. The
    baseline lists no unstable mode."""
    lines = demo_summary(load_params(fins_forward), 10.0, "finsfwd")
    assert "  linear stability: all modes stable = False" in lines
    unstable = [line.split() for line in lines if "UNSTABLE" in line]
    assert [words[1:3] for words in unstable] == [["lateral", "yaw"]]
    lam, doubling = float(unstable[0][5]), float(unstable[0][9])
    assert lam == pytest.approx(1.075, abs=0.005)
    assert doubling == pytest.approx(math.log(2.0) / lam, rel=2e-3)
    assert not any("UNSTABLE" in line for line in demo_summary(load_params(), 10.0))


def test_params_provenance(case, capsys):
    """params --config: a shipped file's own status comments; a generated file (no comments)
    labels the values that differ from the baseline USER and keeps the baseline's status for
    the others."""
    name, p, cfg = case
    rows = {r["name"]: r for r in json.loads(_run(capsys, ["params", "--config", cfg, "--json"]))}
    base = {r["name"]: r for r in parameter_table(load_params())}
    if name == "tcom_32m":
        assert rows["aerostat.length"]["status"] == "SOURCED"
        assert rows["aerostat.volume"]["status"] == "ESTIMATE"
    elif name in GENERATED:
        assert rows["aerostat.volume"]["status"] == "USER"
        assert rows["tether.length"]["status"] == "USER"
        assert rows["aerostat.k1"]["status"] == base["aerostat.k1"]["status"] == "ESTIMATE"
    else:
        assert all(rows[k]["status"] == base[k]["status"] for k in rows)
    ixx = round(1.1 * rows["aerostat.Ixx"]["value"], 1)  # a body still: Ixx is the smallest moment
    over = {r["name"]: r for r in json.loads(_run(
        capsys, ["params", "--config", cfg, "--set", f"aerostat.Ixx={ixx}", "--json"]))}
    assert over["aerostat.Ixx"]["status"] == "USER" and over["aerostat.Ixx"]["value"] == ixx


def test_stability_sweep_and_mode_labels(case, capsys):
    """stability --config (0..20 m/s, 5 m/s steps): every mode stable; the sweep's labels equal
    the single-speed labels at every speed (no grid-dependent swap): the single-speed mode of
    each label is among the sweep's modes of that label (plain or numbered lane) at that speed
    (rel 1e-6)."""
    name, p, cfg = case
    out = json.loads(_run(capsys, ["stability", "--config", cfg, "--wind", "0:20:5", "--json"]))
    assert out["all_stable"] is True
    assert out["tether_length_m"] == p.tether.length
    _no_baseline_numbers(name, _run(capsys, ["stability", "--config", cfg, "--wind", "0:20:10"]))
    sweep = wind_sweep(p, [0.0, 2.0, 5.0])
    for k, u in enumerate(sweep.values):
        single = analyse(p, find_equilibrium(p, float(u)))
        for subset in ("long", "lat"):
            for label in ("pendulum", "yaw" if subset == "lat" else "pitching"):
                m = single.find(subset, label)
                lanes = [t[k].wn for lab, t in sweep.tracks[subset]
                         if lab.split(" (")[0] == label and t[k] is not None]
                assert m is not None
                assert any(w == pytest.approx(m.wn, rel=1e-6, abs=1e-6) for w in lanes), (
                    name, u, subset, label, m.wn, lanes)


def test_sensitivity_and_wind_commands(case, capsys):
    """sensitivity --config: the fin-area range brackets the configured area (x0.67-1.39);
    wind --config: the field reaches above the highest point of the aerostat and is read at the
    configured reference height."""
    name, p, cfg = case
    tab = json.loads(_run(capsys, ["sensitivity", "--config", cfg, "--knob", "fins.planform_area",
                                   "--wind", "5:20:15", "--json"]))
    row = tab["rows"][0]
    area = p.fins.planform_area
    assert row["baseline"] == area
    assert row["low"] == pytest.approx(area * 12 / 18, rel=1e-12)
    assert row["high"] == pytest.approx(area * 25 / 18, rel=1e-12)
    out = json.loads(_run(capsys, ["wind", "--config", cfg, "--preset", "light", "--duration", "300",
                                   "--json"]))
    rows = out["field_shape"][0]
    top = (rows - 1) * 5.0
    z_reach = p.winch.max_length + abs(p.aerostat.leash_z) + p.aerostat.diameter
    assert top > z_reach
    assert out["height"] == pytest.approx(p.wind.turbulence_reference_height)


def test_figure8_on_configured_length(case):
    """Figure 8 (10 s here) runs on the configured tether: the initial condition is the kick
    about that trim (0.1 m, 0.01 rad) and the recorded length is the configured one."""
    name, p, _ = case
    data = figure8_data(p, duration=10.0)
    assert data["tether_length_m"] == p.tether.length
    for var, amp in (("x", 0.1), ("z", 0.1), ("theta", 0.01)):
        assert data["nonlinear"][var][0] == pytest.approx(amp, rel=1e-9)
        assert data["linear"][var][0] == pytest.approx(amp, rel=1e-9)


def test_env_episodes_on_configured_params(case):
    """gym.make(params=...) runs on the configuration: the trim length is the configured one, and
    two short episodes in light turbulence end without failure (finite observations)."""
    name, p, _ = case
    env = gym.make(ENV_ID, params=p, turbulence="light", wind_speed=(8.0, 8.0),
                   max_episode_steps=25)
    for seed in (0, 1):
        obs, info = env.reset(seed=seed)
        b = env.unwrapped
        assert b.task.params_resolved.tether.length == p.tether.length
        done = False
        while not done:
            obs, rew, term, trunc, info = env.step(np.array([0.2], np.float32))
            assert np.all(np.isfinite(obs)) and math.isfinite(rew)
            assert not term, info
            done = trunc
    env.close()


def test_perturbation_presets_scale_with_the_tether():
    """A named perturbation preset's swing and lateral displacement are stated for the 300 m
    reference tether and scale with the configured one (0.05 x the volume on 60 m: x 0.2, so
    the same 1.9 deg swing angle per 10 m of the reference's swing), at construction and as a
    reset option; the pitch kick (an angle) is kept, a dict is taken in metres, and on the
    baseline the presets are exactly the table's."""
    assert REFERENCE_TETHER_LENGTH == load_params().tether.length
    base = TaskConfig(perturbation="mixed", turbulence="none")
    assert {k: base.resolved["perturbation"][k] for k in PERTURBATIONS["mixed"]} == \
        PERTURBATIONS["mixed"]
    small = scale_aerostat(load_params(), 0.05, 60.0)
    assert displacement_scale(small.tether.length) == pytest.approx(0.2, rel=1e-15)
    draws = {}
    for name, params in (("base", None), ("small", small)):
        env = gym.make(ENV_ID, params=params, turbulence="none", perturbation="displacement",
                       wind_speed=10.0)
        infos = [env.reset(seed=3)[1], env.reset(seed=3, options={"perturbation": "mixed"})[1],
                 env.reset(seed=3, options={"perturbation": {"swing": 10.0}})[1]]
        draws[name] = [(i["swing_m"], i["lateral_m"], i["pitch_rad"]) for i in infos]
        env.close()
    for (sb, lb, pb), (ss, ls, ps) in zip(draws["base"][:2], draws["small"][:2], strict=True):
        assert abs(sb) > 1.0 and abs(lb) > 0.5  # a real draw, not a zero
        assert ss == pytest.approx(0.2 * sb, rel=1e-12)
        assert ls == pytest.approx(0.2 * lb, rel=1e-12)
        assert ps == pb  # the pitch kick is an angle: unscaled
    assert draws["small"][2][0] == draws["base"][2][0]  # a dict's metres are kept


def test_reward_swing_terms_are_sized_by_the_tether():
    """The default reward's swing weights follow the tether (reward.sized_weights, k = L / 300
    m): displacement and length / k^2, velocity / k, the rest unchanged; exactly the defaults
    on the baseline. The compiled terms equal those formulas on the step's observation
    (float32 channels: rel 1e-6), and the same-angle preset start then scores its swing alike
    on 0.05 x the volume on 60 m and 8 x on 1000 m (measured -0.865 and -0.792 against the
    baseline's -0.815, within 10 %; with the baseline's weights they would read -0.035 and
    -8.8)."""
    assert {r["term"]: r["weight"] for r in reward_table(tether_length=300.0)} == DEFAULT_WEIGHTS
    sized = {r["term"]: r["weight"] for r in reward_table(tether_length=60.0)}
    assert sized == pytest.approx({**DEFAULT_WEIGHTS, "displacement": 25.0, "velocity": 5.0,
                                   "length": 25.0}, rel=1e-12)
    terms = {}
    for params in (None, scale_aerostat(load_params(), 0.05, 60.0),
                   scale_aerostat(load_params(), 8.0, 1000.0)):
        env = gym.make(ENV_ID, params=params, turbulence="none", perturbation="displacement",
                       wind_speed=10.0)
        k = displacement_scale(env.unwrapped.task.params_resolved.tether.length)
        env.reset(seed=3)
        obs, _, _, _, info = env.step(np.zeros(1, np.float32))
        env.close()
        disp = -float(obs[OBS_DX] ** 2 + obs[OBS_DY] ** 2) / k**2
        vel = -float(obs[OBS_VX] ** 2 + obs[OBS_VY] ** 2) / k
        assert info["reward_displacement"] == pytest.approx(disp, rel=1e-6)
        assert info["reward_velocity"] == pytest.approx(vel, rel=1e-6)
        terms[k] = info["reward_displacement"]
    base = terms[1.0]
    assert base < -0.5  # a real swing
    for k, term in terms.items():
        assert term == pytest.approx(base, rel=0.10), (k, term)


def lqr_damping_check(p, wind=10.0, periods=3.0):
    """(fitted, predicted) closed-loop pendulum damping ratios of an LQR designed for ``p``:
    the nonlinear model starts on the closed-loop pendulum mode (CM displaced 0.5 m x L/300 m)
    and runs ``periods`` predicted periods under the policy (test_lqr's protocol)."""
    p = p.replace(**{"winch.brake_speed": 0.0})
    dt = 0.2
    schedule = LQRSchedule(p, speeds=np.array([wind]), dt=dt)
    design = schedule.designs[0]
    lay = design.linear.layout
    policy = LQRPolicy(p, dt=dt, schedule=schedule)
    dx0, z0 = mode_initial_state(design, "pendulum", 0.5 * p.tether.length / 300.0)
    u = set_point_law(policy, design.x_trim, wind, p, state=np.array([z0]))

    pred = design.mode("pendulum")
    traj = simulate(p, design.x_trim + dx0, periods * pred.period, wind=wind, integrator="rk4",
                    output_dt=dt, u=u)
    assert traj.status == "ok"
    fit = fit_damped_sinusoid(traj.time, traj.cm_pos[:, 0] - design.x_trim[lay.cm_pos][0])
    assert fit.ok and fit.r2 > 0.99, fit
    return fit.zeta, pred.zeta


@pytest.mark.parametrize("name", ["tcom_32m", "gen_small"])
def test_lqr_nonlinear_damping_matches_prediction(name):
    """LQR designed for the configured aerostat and winch: the nonlinear closed-loop pendulum
    damping ratio matches the linear prediction within 20 % (relative) at 10 m/s."""
    fitted, predicted = lqr_damping_check(_params(name))
    assert fitted == pytest.approx(predicted, rel=0.20)


@pytest.mark.slow
@pytest.mark.parametrize("name", CASES)
def test_own_aerostat_full(name, tmp_path, capsys, load_script):
    """Fuller version: 0..20 m/s in 1 m/s steps all stable, the LQR damping check, evaluate and
    demo with --config (resolved parameters recorded), the Figure 8 and Table 2 scripts with
    --config (Figure 8 on the configured length, Table 2 rows in their bands), and train for
    512 steps with --config."""
    p = _params(name)
    cfg = tmp_path / f"{name}.toml"
    cfg.write_text(dumps_toml(p))
    out = json.loads(_run(capsys, ["stability", "--config", str(cfg), "--wind", "0:20:1", "--json"]))
    assert out["all_stable"] is True
    fitted, predicted = lqr_damping_check(p)
    assert fitted == pytest.approx(predicted, rel=0.20)
    _run(capsys, ["evaluate", "--policy", "tension", "--policy", "lqr", "--suite", "damping",
                  "--config", str(cfg), "--no-plots", "--out", str(tmp_path / "ev")])
    assert load_params(tmp_path / "ev" / "params.toml") == p
    report = json.loads((tmp_path / "ev" / "report.json").read_text())
    assert all(r["tether_length_m"] == p.tether.length for r in report)
    assert all(e["ended"] is None for r in report for e in r["scenarios"]["recover"]["episodes"])
    text = _run(capsys, ["demo", "--config", str(cfg), "--suite", "damping", "--wind", "8",
                         "--out", str(tmp_path / "demo")])
    assert f"L = {p.tether.length:g} m" in text
    assert load_params(tmp_path / "demo" / "params.toml") == p
    _no_baseline_numbers(name, text)
    for script, extra in (("reproduce_figure8", []), ("reproduce_table2", ["--no-sensitivity"])):
        out_dir = tmp_path / script
        assert load_script(script).main(["--out", str(out_dir), "--config", str(cfg), *extra]) == 0
    fig8 = json.loads((tmp_path / "reproduce_figure8" / "figure8.json").read_text())
    assert fig8["tether_length_m"] == p.tether.length
    rows = json.loads((tmp_path / "reproduce_table2" / "table2.json").read_text())
    assert all(r["within_tolerance"] for r in rows)
    run = tmp_path / "train"
    _run(capsys, ["train", "--algo", "ppo", "--config", str(cfg), "--timesteps", "512",
                  "--n-envs", "2", "--seed", "0", "--run-dir", str(run), "--no-progress",
                  "--eval-freq", "100000"])
    assert load_params(run / "params.toml") == p


# --- single items of the issue ----------------------------------------------------------------


@pytest.mark.parametrize("name", ["aeros_flightcam", "tcom_32m"])
def test_winch_input_column_is_one_over_tau_at_every_length(name):
    """B[v_w] = 1 / tau (the speed loop's gain) at lengths inside the winch's limits and at the
    limits themselves (rel 1e-8): the one-sided difference at the limits, where a central one
    would straddle the set-point cap and give 1 / (2 tau)."""
    p = load_params(name)
    w = p.winch
    model = Model(p, 5.0)
    iv = model.layout.winch_speed
    for L in (w.min_length, w.min_length + 1e-6, 0.5 * (w.min_length + w.max_length),
              w.max_length - 1e-6, w.max_length):
        eq = find_equilibrium(p, 5.0, length=L)
        B = input_jacobian(model, eq.x, U_FREE.copy(), ACTUATORS, 1e-5)
        assert B[iv, 0] == pytest.approx(1.0 / w.speed_time_constant, rel=1e-8), L


def test_tether_length_outside_winch_limits_is_refused(tmp_path):
    """A file whose tether is longer than winch.max_length (or shorter than min_length) is
    refused, the error naming both fields."""
    text = dumps_toml(load_params())
    for bad in ("length = 450.0", "length = 100.0"):
        f = tmp_path / "bad.toml"
        f.write_text(text.replace("length = 300.0", bad))
        with pytest.raises(ParameterError, match=r"tether\.length.*winch\.(min|max)_length"):
            load_params(f)
    with pytest.raises(ParameterError, match=r"tether\.length.*winch\.max_length"):
        load_params("tcom_32m", {"tether.length": 900.0})


def test_mode_labels_do_not_depend_on_the_grid():
    """Small aerostat (0.15 x the volume on 120 m): on three speed grids the sweep's lateral
    pendulum and yaw at the shared speeds are the same eigenvalues (rel 1e-6)."""
    p = scale_aerostat(load_params(), 0.15, 120.0, 5, -3.0)
    shared = [1.0, 2.0, 4.0, 10.0]
    grids = [np.arange(0.0, 10.01, 0.5), np.array([0.0, 1.0, 2.0, 4.0, 10.0]),
             np.array([1.0, 2.0, 3.0, 4.0, 7.0, 10.0])]
    sweeps = [wind_sweep(p, g) for g in grids]
    for label in ("pendulum", "yaw"):
        curves = [np.interp(shared, sw.values, sw.curve("lat", label, "wn")) for sw in sweeps]
        for c in curves[1:]:
            np.testing.assert_allclose(c, curves[0], rtol=1e-6)


def test_still_air_pendulum_keeps_its_name_on_a_long_grid(tmp_path, capsys):
    """0.004 x the baseline on 1000 m in 8 elements (the audit's 1906 m in 25 shows the same):
    in wind the light tether's drag adds real eigenvalues classed "pendulum" beside the swing,
    at every windy speed, and MAC continuity carries the still-air swing into one of them. On
    0:30:5 those lanes outnumbered it: the U = 0 lateral pendulum was "pendulum (3)", "-" in the
    table and Figure 9. On 0:30:5 and 0:5:5 the table's U = 0 lateral pendulum is now one period
    (rel 1e-9) within the Table 2 band (2 %) of the still-air closed form (110.42 s; linear
    110.45 s), and Figure 9 carries it; at every speed the plain track holds the label's
    lowest-frequency mode, the one Table 2 reads (ModalAnalysis.find)."""
    p = scale_aerostat(load_params(), 0.004, 1000.0, 8, -0.34)
    cfg = tmp_path / "long_light.toml"
    cfg.write_text(dumps_toml(p))
    still_air = []
    for grid in ("0:30:5", "0:5:5"):
        out = json.loads(_run(capsys, ["stability", "--config", str(cfg), "--wind", grid,
                                       "--json"]))
        lateral = [r for r in out["modes"] if r["set"] == "lat" and r["label"] == "pendulum"]
        assert [r["wind_speed_m_s"] for r in lateral] == out["figure9"]["wind_speed_m_s"], grid
        for r in lateral:  # the plain track holds the label's slowest mode, Table 2's
            family = [m["wn_rad_s"] for m in out["modes"] if m["set"] == "lat"
                      and m["label"].startswith("pendulum")
                      and m["wind_speed_m_s"] == r["wind_speed_m_s"]]
            assert r["wn_rad_s"] == min(family), (grid, r["wind_speed_m_s"])
        assert lateral[0]["oscillatory"], grid
        assert out["figure9"]["lat"]["pendulum"]["period_s"][0] == lateral[0]["period_s"]
        still_air.append(lateral[0]["period_s"])
        row = _run(capsys, ["stability", "--config", str(cfg), "--wind", grid]).split(
            "Lateral modes")[1].splitlines()[2]
        assert row.split()[:2] == ["0.00", f"{lateral[0]['period_s']:.2f}"], (grid, row)
    assert still_air[0] == pytest.approx(still_air[1], rel=1e-9)
    closed = closed_form_periods(p)["lat_pendulum"]
    assert abs(still_air[0] / closed - 1) * 100 <= THEORY_TOLERANCE_PCT["lat_pendulum"], (
        still_air, closed)


def test_turbulence_field_sized_from_the_configuration():
    """The field's top row lies above the highest point the aerostat can reach (tether at
    winch.max_length, straight up) and its downwind extent covers the longest tether; the TOML
    keys wind.turbulence / turbulence_model / turbulence_reference_height drive the
    environment's turbulence="config" and the simulator's configured_wind alike."""
    for name in SHIPPED:
        p = load_params(name)
        cfg = sized_turbulence(p, "moderate")
        top = highest_point(p)
        assert top > p.winch.max_length + abs(p.aerostat.leash_z)
        assert top <= cfg.z_max <= top + 2 * cfg.dz
        assert cfg.downwind_extent >= p.winch.max_length
    p = load_params("tcom_32m", {"wind.turbulence": "light", "wind.turbulence_model": "dryden",
                                 "wind.turbulence_reference_height": 550.0})
    env = gym.make(ENV_ID, params=p, turbulence="config", max_episode_steps=5)
    turb = env.unwrapped.task.resolved["turbulence"]
    assert (turb.intensity, turb.model, turb.reference_height) == ("light", "dryden", 550.0)
    env.close()
    wp, wf = configured_wind(p, 30.0, np.random.default_rng(0), speed=8.0)
    assert wf.shape[0] == sized_turbulence(p).heights()[2]
    assert sized_turbulence(p) == turb


def test_families_and_sensitivity_ranges_follow_the_configuration():
    """Figure 9 families relative to the configured length (x0.5-1.25, inside the winch limits)
    and pitch (+-4 deg); sensitivity ranges as factors of the configured values, the documented
    absolute ranges for the baseline (fin area 12-25 m^2, CM shift +-0.3 m, eta_k 0.1-0.5)."""
    p = load_params("tcom_32m")
    assert family_values(p, "tether.length") == (300.0, 450.0, 600.0, 750.0)
    assert family_values(p, "aerostat.trim_pitch_deg") == (-8.0, -4.0, 0.0)
    # a winch limit with more decimals than the family's dedupe rounding: the clamped length
    # stays on the limit (rounded to 9 decimals it fell 3e-10 m below it and was refused)
    odd = load_params(overrides={"winch.min_length": 160.00000000012345})
    lengths = family_values(odd, "tether.length")
    assert lengths[0] == 160.00000000012345 and lengths[1:] == (225.0, 300.0, 375.0)
    assert odd.replace(**{"tether.length": lengths[0]}).tether.length == lengths[0]
    # a heavy line (16 mm, 3800 kg/m^3: 300 m weigh 0.85 of the net lift) can be lifted to
    # 353 m only: the 375 m member, which loading refuses, is left out (it stopped
    # reproduce_figure9.py with that refusal before 0.7.17)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the heavy line's load warning
        heavy = load_params(overrides={"tether.diameter": 0.016, "tether.density": 3800.0})
    reach = heavy.derived.net_lift / paid_out_weight(heavy, 1.0)
    assert 350.0 < reach < 356.0
    assert family_values(heavy, "tether.length") == (150.0, 225.0, 300.0)
    # a slender hull's k3 of 0.96 and an eta_k of 0.9: the ranges end at 1, the coefficients'
    # bound (x1.07 and x1.25 gave 1.03 and 1.125, studied as INVALID before 0.7.17)
    slender = {k.key: k for k in default_knobs(load_params(
        overrides={"aerostat.k3": 0.96, "hull.eta_k": 0.9}))}
    assert (slender["aerostat.k3"].low, slender["aerostat.k3"].high) == pytest.approx(
        (0.96 * 0.584 / 0.7494, 1.0))
    assert (slender["hull.eta_k"].low, slender["hull.eta_k"].high) == pytest.approx((0.225, 1.0))
    # ... and their source text says so (it kept "x0.78-1.07" alone before 0.7.18)
    assert slender["aerostat.k3"].source.endswith("; capped to 0.748-1, the coefficient's "
                                                  "bounds [0, 1]")
    knobs = {k.key: k for k in default_knobs(load_params())}
    assert all("capped" not in k.source for k in knobs.values())  # the baseline's are in range
    for key, (lo, hi) in {"fins.planform_area": (12.0, 25.0), "cm_x_shift": (-0.3, 0.3),
                          "hull.eta_k": (0.1, 0.5), "fins.CL_alpha": (1.2, 2.5),
                          "aerostat.k1": (0.086, 0.188)}.items():
        assert (knobs[key].low, knobs[key].high) == pytest.approx((lo, hi), rel=1e-12), key
    big = {k.key: k for k in default_knobs(p)}
    assert big["cm_x_shift"].high == pytest.approx(0.3 * 32.0 / 18.3, rel=1e-12)
    assert big["fins.planform_area"].low < p.fins.planform_area < big["fins.planform_area"].high


def test_baselines_designed_for_the_configuration():
    """Tension feedback in the configuration's units (baseline: 0.30 m/s per kN and 60 s, rel
    1e-4); LQR weights scaled with the tether (positions x L/300 m, velocities x sqrt(L/300 m),
    reel speed at winch.max_speed); evaluate_policy(params=...) runs the environment on them."""
    base = load_policy("tension", load_params())
    assert (base.gain, base.restore_time) == pytest.approx((0.3, 60.0), rel=1e-4)
    p = scale_aerostat(load_params(), 0.4, 200.0, 6, -2.0).replace(**{"winch.max_speed": 0.7})
    tf = load_policy("tension", p)
    assert tf.max_speed == 0.7
    assert tf.gain == pytest.approx(0.3 * 2.6447 * 0.7 / (p.derived.net_lift / 1e3), rel=1e-12)
    w = scaled_deviations(p)
    r = p.tether.length / 300.0
    assert w["cm_pos"] == pytest.approx(LQR_MAX_DEVIATIONS["cm_pos"] * r, rel=1e-12)
    assert w["cm_vel"] == pytest.approx(LQR_MAX_DEVIATIONS["cm_vel"] * math.sqrt(r), rel=1e-12)
    assert w["reel_speed"] == w["v_set"] == 0.7
    res = evaluate_policy("passive", "damping", params=p)
    assert res["tether_length_m"] == 200.0
    assert load_params_from_text(res["params_toml"]) == p
    rec = res["scenarios"]["recover"]
    assert all(e["ended"] is None for e in rec["episodes"])
    # the episodes ran on this aerostat: its longitudinal pendulum (36.6 s at 1 m/s linear),
    # not the baseline's 44 s, is what the fitted periods see at 5 m/s (within 15 %)
    periods = [e["pendulum_period_s"] for e in rec["episodes"] if e["wind_speed"] == 5.0]
    assert periods and abs(periods[0] / 36.6 - 1.0) < 0.15, periods


def test_shipped_policy_carries_to_the_32m_class_as_the_readme_says():
    """The README's "Your own aerostat" table: the shipped policy, trained on the baseline only,
    damps the swing of the 32 m class (20 m: the 10 m reference swing scaled to its 600 m
    tether) at 10 and 15 m/s as printed there (0.47 / 0.71, the braked winch 0.27 / 0.37;
    within 0.01 of the printed two digits; 0.46 / 0.74 for the policy shipped until 0.7.17)."""
    p = load_params("tcom_32m")
    zeta = {}
    for name in ("shipped", "passive"):
        rec = evaluate_policy(name, "damping", params=p)["scenarios"]["recover"]["episodes"]
        zeta[name] = {e["wind_speed"]: e["pendulum_zeta"] for e in rec}
    assert (zeta["shipped"][10.0], zeta["shipped"][15.0]) == pytest.approx((0.47, 0.71),
                                                                          abs=0.01)
    assert (zeta["passive"][10.0], zeta["passive"][15.0]) == pytest.approx((0.27, 0.37),
                                                                          abs=0.01)


def load_params_from_text(text):
    return params_from_dict(tomllib.loads(text))


def test_observation_limits_and_metrics_follow_a_heavy_aerostat():
    """100 x the baseline's volume on 2000 m: its trim tension (about 220 kN at the winch at
    10 m/s) is above the 100 kN limit sized for the baseline. The tension channels' limits are
    twice its strength, the position and length channels its winch's reach and range (the
    baseline's space is the table's); the observed and the evaluator's tension are the state's
    winch tension (float32 rounding), not the clip."""
    from aerostat_gym.agents.evaluate import run_scenario
    from aerostat_gym.envs import TetheredAerostatEnv
    from aerostat_gym.envs.spaces import CHANNELS, OBS_INDEX, OBS_TENSION, bounds

    base_lo, base_hi = bounds(0)
    lo, hi = bounds(0, load_params())
    assert np.array_equal(lo, base_lo) and np.array_equal(hi, base_hi)
    p = scale_aerostat(load_params(), volume_factor=100.0, tether_length=2000.0, n_elements=6)
    lo, hi = bounds(0, p)
    scale = {c.name: c.scale for c in CHANNELS}
    assert hi[OBS_INDEX["tension"]] == pytest.approx(2 * p.tether.strength / 1e4, rel=1e-6)
    assert lo[OBS_INDEX["dtension"]] == pytest.approx(-2 * p.tether.strength / 1e3, rel=1e-6)
    assert hi[OBS_INDEX["dx"]] == pytest.approx(p.winch.max_length / scale["dx"], rel=1e-6)
    span = p.winch.max_length - p.winch.min_length
    assert hi[OBS_INDEX["dlength"]] == pytest.approx(span / scale["dlength"], rel=1e-6)
    env = TetheredAerostatEnv(params=p, wind_speed=(10.0, 10.0), turbulence="none",
                              perturbation="none")
    obs, _ = env.reset(seed=0)
    T_w = Model(p).end_tensions(env.state)[1]
    assert T_w > 2.0e5
    assert obs[OBS_TENSION] * CHANNELS[OBS_TENSION].scale == pytest.approx(T_w, rel=1e-6)
    ep = run_scenario(load_policy("passive"), "recover", [10.0], [0], env_kwargs={"params": p})
    trim_T = Model(p).end_tensions(find_equilibrium(p, 10.0).x)[1]
    assert np.nanmax(ep.tension) > trim_T > 2.0e5  # the swing loads the tether above its trim


def test_reel_speed_and_body_rate_limits_follow_the_winch_and_the_hull():
    """A 3 m/s winch on the 32 m class: paying out at full command, the length grows at 3 m/s
    and the reel-speed channel reads it (its limit is twice the top speed; it read 2.0, the
    baseline's clip, before 0.7.17). A hull 4 times shorter than the baseline's has body-rate
    limits of 2 rad/s x sqrt(4) (Froude); the baseline's are the table's 2 rad/s."""
    from aerostat_gym.envs import TetheredAerostatEnv
    from aerostat_gym.envs.spaces import CHANNELS, OBS_INDEX, bounds

    p = load_params("tcom_32m", {"winch.max_speed": 3.0, "winch.max_acceleration": 2.0})
    env = TetheredAerostatEnv(params=p, wind_speed=(10.0, 10.0), turbulence="none",
                              perturbation="none")
    env.reset(seed=0)
    i_speed, i_length = OBS_INDEX["reel_speed"], OBS_INDEX["dlength"]
    assert env.observation_space.high[i_speed] == pytest.approx(6.0)
    for _ in range(15):  # 1.5 s at 2 m/s^2 reaches the top speed
        obs = env.step([1.0])[0]
    length = obs[i_length] * CHANNELS[i_length].scale
    obs = env.step([1.0])[0]
    paid = (obs[i_length] * CHANNELS[i_length].scale - length) / env.task.control_step
    assert paid == pytest.approx(3.0, rel=1e-3)
    assert obs[i_speed] * CHANNELS[i_speed].scale == pytest.approx(3.0, rel=1e-3)
    short = scale_aerostat(load_params(), volume_factor=1 / 64, tether_length=75.0,
                           n_elements=6)
    assert short.aerostat.length == pytest.approx(18.3 / 4, rel=1e-3)
    hi, base_hi = bounds(0, short)[1], bounds(0)[1]
    for rate in ("p", "q", "r"):
        assert base_hi[OBS_INDEX[rate]] * CHANNELS[OBS_INDEX[rate]].scale == pytest.approx(2.0)
        assert hi[OBS_INDEX[rate]] == pytest.approx(2.0 * base_hi[OBS_INDEX[rate]], rel=1e-3)


def test_sensitivity_table_columns_stay_aligned_for_a_large_aerostat():
    """30 x the baseline's volume: its product of inertia's range, -8.689e+04 to +8.689e+04
    kg m^2, 20 characters, widens the 17-column range cell instead of shifting its row's
    period columns (before 0.7.17 they stood 3 columns right of the other rows')."""
    p = scale_aerostat(load_params(), volume_factor=30.0, tether_length=900.0, n_elements=6)
    knobs = select_knobs(default_knobs(p), ["aerostat.Ixz", "hull.eta_k"])
    text = format_sensitivity(sensitivity_table(p, knobs, (5.0,)))
    rows = [line for line in text.splitlines() if line.startswith(("product", "hull eff"))]
    assert len(rows) == 2 and "-8.689e+04-8.689e+04" in rows[1]
    slashes = [[i for i, c in enumerate(row) if c == "/"] for row in rows]
    assert len(slashes[0]) == 5 and slashes[0] == slashes[1]


def test_schedules_stop_where_the_winch_motor_cannot_hold_the_trim():
    """0.01 x the baseline's volume on 40 m: its winch motor (8 kN x 0.01 = 80 N) cannot hold
    the trim from about 12 m/s. The LQR, modal and LQG schedules keep the design speeds whose
    trim winch tension is at most the motor force (the next speed's is above it) and run there;
    a motor that holds no trim at all is a clear design error."""
    from aerostat_gym.agents.lqg import LQGSchedule
    from aerostat_gym.agents.modal import ModalSchedule
    from aerostat_gym.agents.scheduling import LQRDesignError, held_trims

    p = scale_aerostat(load_params(), volume_factor=0.01, tether_length=40.0, n_elements=4)
    fmax = p.winch.max_motor_force
    held = held_trims(p, np.arange(2.0, 17.0))
    top = held[-1][0]
    assert all(eq.summary["winch_tension_N"] <= fmax for _, eq in held)
    assert find_equilibrium(p, top + 1.0).summary["winch_tension_N"] > fmax
    assert 8.0 <= top < 16.0
    for schedule in (LQRSchedule(p), ModalSchedule(p), LQGSchedule(p)):
        assert schedule.speeds[-1] == top and schedule.speeds[0] == 2.0
    with pytest.raises(LQRDesignError, match="winch.max_motor_force"):
        held_trims(p.replace(**{"winch.max_motor_force": 1.0}), [5.0, 6.0])


def test_tether_drag_step_is_the_explicit_euler_bound():
    """tether_drag_step is 2 / lambda, lambda = 2 rho Cd d v / mu at v = 15 m/s, computed here
    by hand for the baseline's 6 mm line (0.192 s: not the bound, the Froude 50 ms is) and for
    the 0.0035x aerostat's 0.355 mm line (11.3 ms, below its Froude 19.5 ms, which ended 11 of
    its 8 x 500 severe-turbulence steps at 17-25 m/s as numerical failures)."""
    base = load_params()
    for factor, want_ms in ((1.0, 191.7), (0.0035, 11.34)):
        p = scale_aerostat(base, volume_factor=factor, tether_length=409.0)
        t, rho = p.tether, p.environment.rho_air
        lam = 2.0 * rho * t.Cd_normal * t.diameter * 15.0 / (t.density * math.pi * t.diameter**2 / 4)
        got = tether_drag_step(t.diameter, t.density, t.Cd_normal, rho)
        assert got == pytest.approx(2.0 / lam, rel=1e-12) and 1000 * got == pytest.approx(want_ms, abs=0.05)
    tiny = scale_aerostat(base, volume_factor=0.0035, tether_length=409.0)
    assert tiny.simulation.semi_implicit_dt == pytest.approx(0.01134, abs=1e-5)
    assert advised_semi_implicit_dt(base) == 0.05
    assert tether_drag_step(0.006, 840.0, 0.0, 1.147) == math.inf  # a drag-free line: no bound


def test_a_small_aerostat_file_with_the_baseline_step_warns_at_load(tmp_path):
    """A TOML of the baseline scaled to 0.1x its volume (8.49 m hull) that keeps the 50 ms
    semi-implicit step warns once at load, naming the field, its value and the advised
    0.05 sqrt(8.49 / 18.3) = 0.0341 s; the file scale_aerostat writes, and every shipped file,
    load silently. The advised step is scale_aerostat's for any factor (rel 1e-12)."""
    base = load_params()
    assert (SEMI_IMPLICIT_REFERENCE_HULL_LENGTH, SEMI_IMPLICIT_REFERENCE_DT) == (
        base.aerostat.length, base.simulation.semi_implicit_dt)
    small = scale_aerostat(base, volume_factor=0.1, tether_length=100.0)
    assert advised_semi_implicit_dt(small) == pytest.approx(0.05 * 0.1 ** (1 / 6), rel=1e-12)
    kept = tmp_path / "kept.toml"
    kept.write_text(dumps_toml(small.replace(**{"simulation.semi_implicit_dt": 0.05})))
    with pytest.warns(ParameterWarning) as record:
        load_params(kept)
    assert len(record) == 1
    message = str(record[0].message)
    assert "kept.toml: simulation.semi_implicit_dt = 0.05 s" in message and "<= 0.0341" in message
    scaled = tmp_path / "scaled.toml"
    scaled.write_text(dumps_toml(small))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for source in (scaled, *SHIPPED):
            load_params(source)
    for factor in (0.01, 0.3, 1.0, 10.0):
        p = scale_aerostat(load_params(), volume_factor=factor, tether_length=250.0)
        assert advised_semi_implicit_dt(p) == pytest.approx(p.simulation.semi_implicit_dt, rel=1e-12)


def test_the_small_aerostat_at_its_advised_step_smoke():
    """The fast version of the slow test below: 4,000 of its random-action steps at the
    advised step, every one counted, with no numerical failure, no non-finite observation or
    reward and no observation outside the space."""
    small = scale_aerostat(load_params(), volume_factor=0.1, tether_length=100.0)
    cfg = {**VARIANTS[1], "integrator": "semi-implicit", "turbulence": "severe", "params": small}
    counts = Counter()
    soak_configuration(cfg, 4_000, 8, 0, counts)
    assert counts["steps"] == 4_000
    failures = {k: v for k, v in counts.items() if k.startswith("failure:")}
    assert failures == {} and counts["nonfinite_obs"] == counts["nonfinite_reward"] == 0
    assert counts["obs_outside_space"] == 0


@pytest.mark.slow
def test_the_advised_step_removes_the_small_aerostats_numerical_failures():
    """The numbers of the load warning: the baseline scaled to 0.1x on 100 m, the soak's
    8-25 m/s variant (20 elements, 0.5 s control step, randomised parameters) in severe
    turbulence, 40,000 random-action steps: 1 episode ends as numerical_divergence at 50 ms
    (19 before the semi-implicit snap re-integration of 0.7.6), none at the advised 34 ms."""
    small = scale_aerostat(load_params(), volume_factor=0.1, tether_length=100.0)
    found = {}
    for dt in (0.05, small.simulation.semi_implicit_dt):
        cfg = {**VARIANTS[1], "integrator": "semi-implicit", "turbulence": "severe",
               "params": small.replace(**{"simulation.semi_implicit_dt": dt})}
        counts = Counter()
        soak_configuration(cfg, 40_000, 8, 0, counts)
        found[dt] = counts["termination:numerical_divergence"]
    assert list(found.values()) == [1, 0], found


@pytest.mark.parametrize("factor", [0.01, 0.1, 10.0])
def test_scaling_laws(factor):
    """Geometric similarity with s = factor^(1/3) (aerostat_gym.scaling): lengths x s, areas
    x s^2, masses, volumes and the tether's strength x s^3, inertias x s^5 (rel 1e-12); the
    semi-implicit step x sqrt(s) below the source's size, unchanged above it, and no longer
    than the thinner line's drag bound (0.01x: 19.3 ms against the Froude 23.2 ms)."""
    base = load_params()
    p = scale_aerostat(base, volume_factor=factor, tether_length=250.0)
    s = factor ** (1.0 / 3.0)
    pairs = [(p.aerostat.length, base.aerostat.length * s),
             (p.fins.planform_area, base.fins.planform_area * s**2),
             (p.aerostat.volume, base.aerostat.volume * s**3),
             (p.aerostat.mass, base.aerostat.mass * s**3),
             (p.tether.strength, base.tether.strength * s**3),
             (p.aerostat.Iyy, base.aerostat.Iyy * s**5),
             (p.simulation.semi_implicit_dt,
              min(base.simulation.semi_implicit_dt * min(1.0, math.sqrt(s)),
                  tether_drag_step(p.tether.diameter, p.tether.density, p.tether.Cd_normal,
                                   p.environment.rho_air)))]
    for got, want in pairs:
        assert got == pytest.approx(want, rel=1e-12)
    assert p.tether.length == 250.0 and p.winch.max_length == pytest.approx(250.0 * 4 / 3)


def test_each_aerostat_mode_label_is_held_once():
    """TCOM 32M, as shipped and with its CM moved by the sensitivity table's +-0.52 m, 0-20 m/s:
    where pitching, the axial spring and the first tether harmonic mix (40-50 % tether each),
    each aerostat label names one oscillatory mode per set, the keeper carries the larger share
    of its group, and the renamed mode is a tether mode with at least a fifth of its energy in
    the tether; the first tether harmonic is found at every speed (it was missing at 6-9 m/s
    and with the CM moved, the sensitivity table's 'n/a')."""
    from aerostat_gym.analysis.modes import AEROSTAT_MODES, TETHER_SHARE_TO_RENAME
    from aerostat_gym.analysis.sensitivity import _shift_cm

    base = load_params("tcom_32m")
    for p in (base, _shift_cm(base, -0.5246), _shift_cm(base, 0.5246)):
        eq = None
        for u in np.arange(0.0, 20.01, 1.0):
            eq = find_equilibrium(p, float(u), guess=eq)
            an = analyse(p, eq)
            for subset, groups in AEROSTAT_MODES.items():
                modes = [m for m in getattr(an, subset) if m.oscillatory]
                for label in groups:
                    assert sum(m.label == label for m in modes) <= 1, (u, subset, label)
            tether1 = an.find("long", "tether 1st harmonic")
            assert tether1 is not None and tether1.oscillatory, u
            assert tether1.energy["tether_x"] >= TETHER_SHARE_TO_RENAME
    an = analyse(base, find_equilibrium(base, 6.0))
    pitching, tether1 = an.find("long", "pitching"), an.find("long", "tether 1st harmonic")
    assert pitching.energy["pitch"] > tether1.energy["pitch"] > 0.3


def test_a_repeated_tether_harmonic_gives_its_number_to_the_missing_one():
    """3.475 x the baseline on 556 m, 29 elements, trimmed -8.07 deg, in still air: the aerostat
    pitches with the first tether harmonic (41 % pitch) and the tether's shape under the
    confluence point changes sign once, so its sign count alone names it the second harmonic
    beside the true one (1.68 s). The longer-period one takes the missing first: 3.094 s,
    -8.3 % from the closed form's 3.374 s (band 10 %; the row read nan before)."""
    p = scale_aerostat(load_params(), 3.475, 556.0, 29, -8.07)
    long_modes = analyse(p, find_equilibrium(p, 0.02)).long
    osc = [m.label for m in long_modes if m.oscillatory]
    assert len(osc) == len(set(osc)), osc
    first = next(m for m in long_modes if m.label == "tether 1st harmonic")
    second = next(m for m in long_modes if m.label == "tether 2nd harmonic")
    assert first.period == pytest.approx(3.094, abs=0.002) and first.energy["pitch"] > 0.3
    assert second.period == pytest.approx(1.678, abs=0.002) and second.energy["tether_x"] > 0.95
    row = {r["key"]: r for r in table2(p)}["tether_1st"]
    assert row["within_tolerance"] and row["calm_diff_pct"] == pytest.approx(-8.30, abs=0.05), row
