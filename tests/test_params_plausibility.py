"""Implausible parameter files are refused at the loading door (audit of "bring your own
aerostat" flows): unit slips, points outside the hull, broken symmetry, the compiled core's and
the model's limits, a UTF-8 byte-order mark, and the trim of a small net-lift margin.

Every refusal is a ParameterError (unit slips: its subclass ImplausibleParameterError) raised by
load_params, from a file and from overrides alike, naming the field; unusual but possible values
load with a ParameterWarning; real aerostats load without either."""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import pytest

import aerostat_gym
from aerostat_gym.analysis.trim import REL_TOL, TrimError, find_equilibrium
from aerostat_gym.params import (
    MAX_WIND_SPEED,
    RK4_SAFETY_LIMIT,
    ImplausibleParameterError,
    ParameterError,
    ParameterWarning,
    dumps_toml,
    load_params,
    params_to_dict,
    shipped_configs,
)
from aerostat_gym.scaling import scale_aerostat

BASE = load_params()

#: the small-margin aerostats below cannot carry winch.max_length of tether: their load warns
#: (tested in test_unusual_values_warn); the trim tests need not repeat it
pytestmark = pytest.mark.filterwarnings(
    "ignore:.*does not exceed the weight of winch.max_length")


def _small7():
    """The baseline scaled to a 7 m hull on a 50 m tether (the audit's small aerostat)."""
    return scale_aerostat(BASE, (7.0 / 18.3) ** 3, 50.0, 5)


def _set_in_toml(text: str, section: str, key: str, value: str) -> str:
    """``key = value`` in ``[section]`` of a TOML text (the first occurrence after the header)."""
    head = text.index(f"[{section}]\n")
    m = re.compile(rf"^{re.escape(key)} = .*$", re.M).search(text, head)
    assert m, (section, key)
    return text[:m.start()] + f"{key} = {value}" + text[m.end():]


def _load_quietly(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ParameterWarning)
        return load_params(*args, **kwargs)


# --- real aerostats load without errors or warnings ----------------------------------------------

#: (volume factor, tether length [m], elements): hulls from 5 m to 70 m, tethers from 20 m to 5 km
REAL = {
    "5m_hull_20m_tether": ((5.0 / 18.3) ** 3, 20.0, 2),
    "7m_hull_50m_tether": ((7.0 / 18.3) ** 3, 50.0, 5),
    "0.011x_884m": (0.011, 884.0, 2),
    "0.003x_1053m": (0.003, 1053.0, 29),
    "35m_hull_1km": ((35.0 / 18.3) ** 3, 1000.0, 20),
    "70m_hull_5km": ((70.0 / 18.3) ** 3, 5000.0, 50),
}


@pytest.mark.parametrize("name", shipped_configs())
def test_shipped_configurations_load_without_warnings(name):
    _load_quietly(name)  # a ParameterWarning is an error here


@pytest.mark.parametrize("name", list(REAL))
def test_real_aerostats_from_5_to_70_m_load_without_warnings(tmp_path, name):
    p = scale_aerostat(BASE, *REAL[name])
    f = tmp_path / "own.toml"
    f.write_text(dumps_toml(p))
    assert _load_quietly(f) == p


@pytest.mark.parametrize("over", [
    {"tether.youngs_modulus": 200e9, "tether.density": 7850.0},   # steel wire
    {"tether.youngs_modulus": 70e9, "tether.density": 1440.0},    # aramid (Kevlar)
    {"tether.youngs_modulus": 65e9, "tether.density": 1400.0},    # Vectran
    {"tether.density": 4500.0},                                   # armoured conductor tether
    {"hull.Cdc": 0.3}, {"aerostat.leash_z": -18.3},
    {"simulation.rk4_safety": RK4_SAFETY_LIMIT},
    {"wind.speed": MAX_WIND_SPEED}, {"tether.anchor_position": [0.0, 0.0, 120.0]},
    {"tether.length": 201.0}, {"tether.length": 400.0},  # within a factor 1.5 of the 300 m
])
def test_real_variants_load_without_warnings(over):
    _load_quietly(overrides=over)


def test_cruciform_fins_load_without_warnings():
    """Four panels at +-45 and +-135 deg (an X tail) are two mirrored pairs."""
    panels = [{"name": n, "roll_angle_deg": phi, "cp_position": [-5.715, y, z]}
              for n, phi, y, z in (("ul", 45.0, 3.2937, 4.0117), ("ur", -45.0, -3.2937, 4.0117),
                                   ("ll", 135.0, 3.2937, -2.5757), ("lr", -135.0, -3.2937, -2.5757))]
    _load_quietly(overrides={"fins.panels": panels})


# --- unit slips and impossible geometry: refused from a file and from overrides --------------------

SMALL7 = _small7()
X_NOSE_7 = SMALL7.aerostat.nose_position[0]

#: (base, section, key, value, error class, texts the message must contain)
REFUSED = [
    (BASE, "tether", "youngs_modulus", 37.4e3, ImplausibleParameterError,
     ("tether.youngs_modulus = 37400 Pa", "looks like MPa written as Pa")),
    (BASE, "tether", "youngs_modulus", 37.4e15, ImplausibleParameterError,
     ("tether.youngs_modulus", "stiffer than diamond")),
    # a 1 mm line left with the 6 mm line's 35.6 kN strength: the modulus is right (no unit
    # slip to suggest; 0.7.16 suggested "MPa written as Pa", which is then stiffer than
    # diamond), the strength does not fit the diameter: 25 % strain at 7343 N
    (BASE, "tether", "diameter", 0.001, ImplausibleParameterError,
     ("tether.youngs_modulus = 3.74e+10 Pa gives EA = 2.937e+04 N on the 1 mm tether",
      "tether.strength does not fit tether.diameter: this line would stretch 25 % at 7343 N")),
    (BASE, "tether", "density", 0.975, ImplausibleParameterError,
     ("tether.density = 0.975", "looks like g/cm^3 written as kg/m^3")),
    (BASE, "aerostat", "diameter", 770.0, ImplausibleParameterError,
     ("aerostat.diameter = 770", "looks like aerostat.diameter in cm")),
    (BASE, "aerostat", "length", 1830.0, ImplausibleParameterError,
     ("aerostat.length = 1830", "looks like aerostat.length in cm")),
    (BASE, "simulation", "rk4_safety", 2.0, ImplausibleParameterError,
     ("simulation.rk4_safety = 2", "1.02")),
    (BASE, "simulation", "rk4_safety", 90.0, ImplausibleParameterError,
     ("simulation.rk4_safety = 90", "percentage")),
    # 2.4 x the baseline's advised 50 ms: past the measured failure edge (1.2-1.5 x)
    (BASE, "simulation", "semi_implicit_dt", 0.12, ImplausibleParameterError,
     ("simulation.semi_implicit_dt = 0.12 s", "2 x the 0.05 s advised", "<= 0.05")),
    (SMALL7, "aerostat", "nose_position", [30.0, 0.0, 0.25], ImplausibleParameterError,
     ("aerostat.nose_position x = 30", "behind the tail")),
    (SMALL7, "aerostat", "nose_position", [-3.1, 0.0, 0.25], ImplausibleParameterError,
     ("aerostat.nose_position x = -3.1", "ahead of the nose", "sign was flipped")),
    (BASE, "aerostat", "cb_position", [9.5, 0.0, 0.718], ImplausibleParameterError,
     ("aerostat.cb_position x = 9.5", "outside the hull")),
    (BASE, "aerostat", "leash_z", -1155.0, ImplausibleParameterError,
     ("aerostat.leash_z = -1155", "looks like cm written as m")),
    (BASE, "aerostat", "leash_z", 11.55, ImplausibleParameterError,
     ("aerostat.leash_z = 11.55", "must be < 0", "sign was flipped")),
    (BASE, "aerostat", "leash_z", 0.0, ImplausibleParameterError, ("aerostat.leash_z = 0",)),
    (BASE, "aerostat", "cb_position", [0.02, 1.0, 0.25], ImplausibleParameterError,
     ("aerostat.cb_position", "y = 1 m", "symmetry")),
    (BASE, "aerostat", "nose_position", [8.21, -0.5, 0.718], ImplausibleParameterError,
     ("aerostat.nose_position", "y = -0.5 m", "symmetry")),
    (BASE, "hull", "Cdc", 12.0, ImplausibleParameterError, ("hull.Cdc = 12",)),
    (BASE, "wind", "speed", 500.0, ParameterError, ("wind.speed = 500 m/s", "100 m/s")),
    (BASE, "tether", "anchor_position", [0.0, 0.0, -5.0], ParameterError,
     ("tether.anchor_position", "below the ground")),
]


def _ids(case):
    return f"{case[1]}.{case[2]}={case[3]!r}"


@pytest.mark.parametrize("base, section, key, value, error, texts", REFUSED,
                         ids=[_ids(c) for c in REFUSED])
def test_refused_in_a_file(tmp_path, base, section, key, value, error, texts):
    text = _set_in_toml(dumps_toml(base), section, key, repr(list(value) if isinstance(
        value, list) else value))
    f = tmp_path / "slip.toml"
    f.write_text(text)
    with pytest.raises(error) as err:
        load_params(f)
    for t in texts:
        assert t in str(err.value)


@pytest.mark.parametrize("base, section, key, value, error, texts", REFUSED,
                         ids=[_ids(c) for c in REFUSED])
def test_refused_as_an_override(tmp_path, base, section, key, value, error, texts):
    f = tmp_path / "own.toml"
    f.write_text(dumps_toml(base))
    with pytest.raises(error) as err:
        load_params(f, overrides={f"{section}.{key}": value})
    for t in texts:
        assert t in str(err.value)


def test_fin_outside_the_hull_is_refused():
    """A fin 100 m aft of the CM on a 7 m hull, and one ahead of the nose."""
    panels = [dict(p) for p in params_to_dict(SMALL7)["fins"]["panels"]]
    for x, where in ((-100.0, "fins.panels[0].cp_position x = -100"),
                     (X_NOSE_7 + 1.0, "fins.panels[0].cp_position x = ")):
        bad = [{**panels[0], "cp_position": [x, 0.0, 2.2]}] + panels[1:]
        with pytest.raises(ImplausibleParameterError, match=re.escape(where)) as err:
            load_params(overrides={**{k: v for k, v in _flat(SMALL7).items()},
                                   "fins.panels": bad})
        assert "aft of the tail" in str(err.value)


def test_fin_slightly_aft_of_the_tail_loads():
    """Fins may overhang the tail (by up to a quarter hull length)."""
    a = SMALL7.aerostat
    tail = a.nose_position[0] - a.length
    panels = [{**p, "cp_position": [tail - 0.2 * a.length, *p["cp_position"][1:]]}
              for p in params_to_dict(SMALL7)["fins"]["panels"]]
    with warnings.catch_warnings():
        warnings.simplefilter("error", ParameterWarning)
        load_params(overrides={**_flat(SMALL7), "fins.panels": panels})


def test_fin_far_off_the_axis_is_refused():
    panels = [dict(p) for p in params_to_dict(BASE)["fins"]["panels"]]
    panels[0]["cp_position"] = [-5.715, 0.0, 53.76]
    with pytest.raises(ImplausibleParameterError, match=r"fins\.panels\[0\]\.cp_position"):
        load_params(overrides={"fins.panels": panels})


def test_swapped_length_and_diameter_are_refused():
    with pytest.raises(ImplausibleParameterError) as err:
        load_params(overrides={"aerostat.length": 7.7, "aerostat.diameter": 18.3,
                               "hull.l_h": 5.0})
    assert "aerostat.length / aerostat.diameter" in str(err.value)
    assert "swapped" in str(err.value)


def _flat(p) -> dict:
    """Every input of ``p`` as dotted overrides (to load another aerostat through the door)."""
    return {f"{sec}.{k}": v for sec, table in params_to_dict(p).items() for k, v in table.items()}


# --- more than MAX_FIN_PANELS fin panels ----------------------------------------------------------

def test_eight_fin_panels_are_a_parameter_error_at_load(tmp_path):
    panels = params_to_dict(BASE)["fins"]["panels"]
    eight = [{**panels[i % 3], "name": f"f{i}"} for i in range(8)]
    with pytest.raises(ParameterError, match=r"fins\.panels has 8 panels; at most 6") as err:
        load_params(overrides={"fins.panels": eight})
    assert not isinstance(err.value, ImplausibleParameterError)
    with pytest.raises(ParameterError, match=r"fins\.panels"):  # and on every replace
        BASE.replace(**{"fins.panels": eight})


def test_rk4_limit_matches_the_integrators_measured_edge():
    """params' RK4 safety limit is the one the integrator's documentation gives."""
    from aerostat_gym.physics import integrators

    assert f"{RK4_SAFETY_LIMIT:g} times this bound" in integrators.rk4_step.__doc__


# --- unusual but possible: a ParameterWarning naming the field ---------------------------------

@pytest.mark.parametrize("over, field", [
    ({"hull.Cdc": 2.0}, "hull.Cdc = 2"),
    ({"tether.density": 300.0}, "tether.density = 300"),
    ({"tether.density": 12000.0}, "tether.density = 12000"),
    ({"tether.youngs_modulus": 3.0e9}, "tether.youngs_modulus = 3e+09"),  # nylon-like: 42 %
    ({"aerostat.volume": 300.0, "aerostat.mass": 120.0}, "aerostat.volume = 300"),
    # 72.5 N of net lift carries 311 m of the 0.233 N/m line: 400 m (93.2 N) may be paid out
    ({"aerostat.mass": 587.9}, "winch.max_length = 400 m of tether (93.2 N): paid out past 311 m"),
    # the tether shortened without the turbulence's height (300 m, the baseline's tether): the
    # aerostat would fly in 300 m turbulence at 150 m (the warning is new in 0.7.17)
    ({"tether.length": 150.0}, "wind.turbulence_reference_height = 300 m is far from the "
                               "aerostat's height (tether.length = 150 m)"),
])
def test_unusual_values_warn(over, field):
    with pytest.warns(ParameterWarning, match=re.escape(field)):
        load_params(overrides=over)


def test_the_envs_tether_length_warns_of_the_turbulence_height():
    """The env's ``tether_length`` (or a ``tether.length`` override) moves the aerostat but not
    the turbulence's reference height: a turbulent env warns when that leaves the height a
    factor 1.5 off (0.7.18), at the caller's line; a calm one, or one within the factor, does
    not."""
    import warnings

    import gymnasium as gym

    import aerostat_gym  # noqa: F401  (registers the tasks)
    from aerostat_gym.envs.env import TetheredAerostatEnv

    text = "wind.turbulence_reference_height = 300 m is far from the aerostat's height " \
           "(tether.length = 160 m)"
    for kw in ({"tether_length": 160.0}, {"overrides": {"tether.length": 160.0}}):
        with pytest.warns(ParameterWarning, match=re.escape(text)) as record:
            TetheredAerostatEnv(turbulence="light", **kw)
        assert record[0].filename == __file__  # the user's line, not the package's
    with pytest.warns(ParameterWarning, match=re.escape(text)) as record:
        gym.make("TetheredAerostat-v0", turbulence="light", tether_length=160.0)
    assert record[0].filename == __file__  # past gymnasium's frames too
    with warnings.catch_warnings():
        warnings.simplefilter("error", ParameterWarning)
        TetheredAerostatEnv(turbulence="light", tether_length=250.0)  # 300 / 250 = 1.2
        TetheredAerostatEnv(turbulence="none", tether_length=160.0)
        TetheredAerostatEnv(turbulence="light", overrides={  # moved with the tether
            "tether.length": 160.0, "wind.turbulence_reference_height": 160.0})


def test_fins_without_a_mirror_panel_warn():
    panels = params_to_dict(BASE)["fins"]["panels"][:2]  # upper and port, no starboard
    with pytest.warns(ParameterWarning, match=r"fins\.panels\[1\] \('port'.*no mirror panel"):
        load_params(overrides={"fins.panels": panels})


def test_studies_may_still_move_values_past_the_door():
    """Params.replace checks the limits of the core but not plausibility: a weightless tether
    or RK4 past its stability bound stay available to tests of those regimes."""
    assert BASE.replace(**{"simulation.rk4_safety": 1.4}).simulation.rk4_safety == 1.4
    assert BASE.replace(**{"tether.density": 1e-3}).tether.density == 1e-3
    with pytest.raises(ImplausibleParameterError, match=r"simulation\.rk4_safety"):
        load_params(overrides={"simulation.rk4_safety": 1.4})


@pytest.mark.parametrize("over, texts", [
    ({"tether.density": 0.975}, ("tether.density = 0.975", "looks like g/cm^3 written as kg/m^3")),
    ({"tether.youngs_modulus": 37.4e3}, ("tether.youngs_modulus = 37400 Pa",
                                         "looks like MPa written as Pa")),
    ({"simulation.rk4_safety": 1.4}, ("simulation.rk4_safety = 1.4", "1.02")),
])
def test_the_env_is_a_door_too(over, texts):
    """gym.make's overrides and a Params built by replace() meet the loader's bounds when the
    env is made (a study that needs such values runs the simulator, past the door)."""
    import gymnasium as gym

    import aerostat_gym  # noqa: F401  (registers the tasks)
    for make in (lambda: gym.make("TetheredAerostat-v0", overrides=over),
                 lambda: gym.make("TetheredAerostat-v0", params=BASE.replace(**over))):
        with pytest.raises(ImplausibleParameterError) as err:
            make()
        for t in texts:
            assert t in str(err.value)


# --- a UTF-8 byte-order mark -------------------------------------------------------------------

def test_a_utf8_bom_is_accepted(tmp_path):
    f = tmp_path / "bom.toml"
    f.write_bytes(b"\xef\xbb\xbf" + dumps_toml(BASE).encode("utf-8"))
    assert _load_quietly(f) == BASE


def test_a_bom_in_the_middle_is_still_invalid_toml(tmp_path):
    f = tmp_path / "bom2.toml"
    text = dumps_toml(BASE)
    f.write_bytes(text.encode("utf-8").replace(b"[tether]", b"\xef\xbb\xbf[tether]", 1))
    with pytest.raises(ParameterError, match="invalid TOML"):
        load_params(f)


# --- trim with a small net-lift margin -----------------------------------------------------------

LOW_MARGIN = {"aerostat.mass": 587.9}  # net lift 72.5 N, tether weight 69.9 N
COMFORTABLE = {"aerostat.mass": 586.0}  # net lift 91.2 N


def _margin(p) -> float:
    """Net lift minus the tether's weight [N]: the winch tension in still air."""
    return p.derived.net_lift - p.derived.tether_weight


def _with_margin(p, share: float):
    """``p`` with the aerostat's mass set so that the margin is ``share`` of the net lift."""
    d = p.derived
    net_lift = d.tether_weight / (1.0 - share)
    return p.replace(**{"aerostat.mass": (d.buoyancy - net_lift) / p.environment.g})


def _continued_in_mass(p, wind_speed: float, start):
    """The reference equilibrium: the trim of ``p`` with the lighter aerostat ``start`` (a wider
    margin) at this wind speed, continued in aerostat mass to ``p``'s: another path, through
    another Newton start, to the same equilibrium."""
    near = find_equilibrium(start, wind_speed)
    ref = find_equilibrium(p, wind_speed, guess=near)
    assert ref.residual <= REL_TOL
    return ref


def _assert_same_trim(eq, ref):
    """Two trims agree to 1 micrometre (positions) and microradian (attitude), and their end
    tensions to 1 ppm; both are flying equilibria."""
    assert eq.residual <= REL_TOL
    assert max(abs(eq.x - ref.x)) < 1e-6
    for end in ("top_tension_N", "winch_tension_N"):
        assert eq.summary[end] == pytest.approx(ref.summary[end], rel=1e-6)
    assert eq.summary["min_tension_N"] > 0 and eq.summary["aerostat_position_m"][2] > 0


def test_low_margin_trims_at_10_m_s():
    """The audit's case at 10 m/s is the equilibrium that a continuation in aerostat mass (from
    586 kg, 91 N net lift) finds."""
    p = load_params(overrides=LOW_MARGIN)
    d = p.derived
    assert d.net_lift == pytest.approx(72.5, abs=0.05)
    assert d.tether_weight == pytest.approx(69.9, abs=0.05)
    _assert_same_trim(find_equilibrium(p, 10.0),
                      _continued_in_mass(p, 10.0, load_params(overrides=COMFORTABLE)))


@pytest.mark.parametrize("wind_speed", [0.5, 1.0, 2.0, 3.0, 5.0])
def test_low_margin_trims_in_light_wind(wind_speed):
    """In light wind the lower tether of the audit's case carries a few newtons (9 N at 1 m/s)
    and the trim is ill-conditioned: Newton's force-decrease line search crept in steps of
    1/64 to 1/8 and the continuation in wind stalled at 0.078 m/s after 5 to 25 s. With the
    natural monotonicity test it takes full steps (34 iterations at 1 m/s, 0.1 s) to the
    equilibrium a continuation in mass reaches."""
    p = load_params(overrides=LOW_MARGIN)
    eq = find_equilibrium(p, wind_speed)
    assert eq.iterations < 100
    _assert_same_trim(eq, _continued_in_mass(p, wind_speed, load_params(overrides=COMFORTABLE)))


def test_low_margin_trim_leaves_the_still_air_line_as_u_squared():
    """Closed form at the light-wind end: in still air the tether hangs vertical, carrying the
    net lift at the top and the margin (2.6 N) at the winch. The wind's forces on the hull and
    the tether grow as U^2, so the winch tension rises above the margin as U^2: doubling the
    wind from 0.1 to 0.2 m/s quadruples the excess (4.06: the blow-by, 0.06 to 0.24 deg,
    bends the line a little)."""
    p = load_params(overrides=LOW_MARGIN)
    still = find_equilibrium(p, 0.0).summary
    assert still["winch_tension_N"] == pytest.approx(_margin(p), rel=1e-9)
    assert still["top_tension_N"] == pytest.approx(p.derived.net_lift, rel=1e-9)
    excess = [find_equilibrium(p, u).summary["winch_tension_N"] - _margin(p) for u in (0.1, 0.2)]
    assert 0.02 < excess[0] < 0.03  # N
    assert excess[1] / excess[0] == pytest.approx(4.0, rel=0.03)


def test_the_heaviest_loadable_aerostat_trims():
    """The heaviest aerostat whose net lift exceeds the tether's weight weighs (buoyancy -
    tether weight) / g = 588.168 kg on the baseline; 1 g more is refused at load. 1 g less (a
    margin of 0.01 N) trims at 1 m/s, to the equilibrium continued in mass from 587.9 kg."""
    d, g = BASE.derived, BASE.environment.g
    heaviest = (d.buoyancy - d.tether_weight) / g
    assert heaviest == pytest.approx(588.168, abs=5e-4)
    with pytest.raises(ParameterError, match="cannot lift its tether"):
        load_params(overrides={"aerostat.mass": heaviest + 1e-3})
    p = load_params(overrides={"aerostat.mass": heaviest - 1e-3})
    assert _margin(p) == pytest.approx(1e-3 * g)
    _assert_same_trim(find_equilibrium(p, 1.0),
                      _continued_in_mass(p, 1.0, load_params(overrides=LOW_MARGIN)))


@pytest.mark.parametrize("name, wind_speed", [("7m_hull_50m_tether", 1.0),
                                              ("7m_hull_50m_tether", 10.0), ("tcom_32m", 1.0)])
def test_other_aerostats_with_a_1_percent_margin_trim(name, wind_speed):
    """A margin of 1 % of the net lift on a small aerostat (stalled at 0.016 m/s, at 1 and at
    10 m/s alike) and on the 32 m one (stalled at 0.094 m/s): the trim is the one continued
    in mass from a margin of 20 %."""
    p = load_params(name) if name in shipped_configs() else scale_aerostat(BASE, *REAL[name])
    low = _with_margin(p, 0.01)
    assert _margin(low) == pytest.approx(0.01 * low.derived.net_lift)
    _assert_same_trim(find_equilibrium(low, wind_speed),
                      _continued_in_mass(low, wind_speed, _with_margin(p, 0.2)))


def test_a_paid_out_tether_heavier_than_the_net_lift_needs_wind():
    """400 m paid out (the winch's longest) weigh 93.2 N, more than the 72.5 N of net lift: at
    2 m/s the model's only equilibrium hangs the tether 17 m below the ground (it has no ground),
    which is refused naming the weights; at 10 m/s the hull's lift carries the tether."""
    p = load_params(overrides=LOW_MARGIN)
    assert p.winch.max_length == 400.0
    with pytest.raises(TrimError) as err:
        find_equilibrium(p, 2.0, length=400.0)
    msg = str(err.value)
    assert "below the ground" in msg and "U = 2 m/s" in msg
    assert "net lift (72.5 N)" in msg and "400 m of tether paid out (93.2 N)" in msg
    s = find_equilibrium(p, 10.0, length=400.0).summary
    assert s["elevation_at_winch_deg"] > 0 and s["min_tension_N"] > 0


def test_a_paid_out_tether_heavier_than_the_net_lift_has_no_still_air_trim():
    """Closed form: in still air the line hangs vertical and the winch carries net lift minus
    the weight paid out, here 72.5 - 93.2 = -20.7 N: no flying equilibrium, refused before any
    Newton iteration (the continuation used to fail after 1.6 s), naming both forces."""
    p = load_params(overrides=LOW_MARGIN)
    with pytest.raises(TrimError) as err:
        find_equilibrium(p, 0.0, length=400.0)
    msg = str(err.value)
    assert "still air" in msg and "net lift (72.5 N)" in msg and "paid out (93.2 N)" in msg
    assert find_equilibrium(p, 0.0, length=300.0).summary["winch_tension_N"] == pytest.approx(
        p.derived.net_lift - p.derived.mass_per_length * 300.0 * p.environment.g, rel=1e-9)


def test_low_margin_failure_names_the_margin():
    """Where the trim cannot be reached (here: an unreachable tolerance), the error gives the
    net lift, the tether's weight, the margin between them and the wind speed, and fails fast
    (0.3 s)."""
    p = load_params(overrides=LOW_MARGIN)
    with pytest.raises(TrimError) as err:
        find_equilibrium(p, 10.0, tol=1e-30)
    msg = str(err.value)
    assert "net lift (72.5 N)" in msg and "tether (69.9 N)" in msg and "by only 2.6 N" in msg
    assert "U = 10 m/s" in msg and "aerostat.mass" in msg


def test_a_comfortable_margin_keeps_the_plain_message():
    with pytest.raises(TrimError) as err:
        find_equilibrium(BASE, 10.0, tol=1e-30)
    assert "net lift" not in str(err.value)
    assert math.isfinite(BASE.derived.net_lift)


def test_a_tether_diameter_whose_area_overflows_is_named():
    """A diameter of 1e200 m squares past the largest float: the loader refuses the tether's
    infinite weight naming tether.diameter (was Python's OverflowError from the derived area)."""
    with pytest.raises(ParameterError, match=r"inf N, tether\.diameter"):
        load_params(overrides={"tether.diameter": 1e200})


@pytest.mark.parametrize("over, message", [
    ({"tether.damping_ratio": 1e6}, "tether.damping_ratio = 1e+06 lies outside [0, 2]"),
    ({"hull.CD0": 1e300}, "hull.CD0 = 1e+300 lies outside [0, 2]"),
    ({"hull.CD0": 2.9}, "; looks like a percentage written as a fraction"),
    ({"fins.CL_alpha": 1e6}, "fins.CL_alpha = 1e+06 lies outside [0, 12.5664]"),
    ({"environment.g": 1e-300}, "environment.g = 1e-300 lies outside [0.1, 100]"),
    ({"environment.rho_air": 1e300}, "environment.rho_air = 1e+300 lies outside [0.001, 100]"),
])
def test_values_no_aerostat_has_are_named(over, message):
    """PLAUSIBLE_RANGES: each refused on load naming the field (a CD0 of 1e300 stalled the trim
    with a residual of 1e277, a damping ratio of 1e6 diverged every episode, an air density of
    1e300 printed a 300-digit net lift); a ratio of 1.7 loads."""
    with pytest.raises(ImplausibleParameterError) as err:
        load_params(overrides=over)
    assert message in str(err.value) and len(str(err.value)) < 200
    assert load_params(overrides={"tether.damping_ratio": 1.7}).tether.damping_ratio == 1.7


def test_a_negative_hull_area_integral_is_refused():
    """I1 = A_h, the hull's cross-section area at the fins' root, cannot be negative."""
    with pytest.raises(ParameterError, match=r"hull\.I1 must be >= 0, got -1\.0"):
        load_params(overrides={"hull.I1": -1.0})


def test_a_misspelt_status_word_warns_naming_the_line(tmp_path):
    """A status comment with SORCED, ESTIMATED or CALIBRATED would silently report the value
    with the baseline's status: a ParameterWarning names the line, the word and the nearest
    status; the shipped files have none."""
    base = (Path(aerostat_gym.__file__).parent / "data" / "aeros_flightcam.toml").read_text()
    lines = base.splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("mass ="))
    lines[k] = lines[k].replace("DERIVED", "DERIVD")
    path = tmp_path / "slip.toml"
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(ParameterWarning, match=rf"line {k + 1}: 'DERIVD' is no status word "
                      r"\(did you mean 'DERIVED'\?"):
        load_params(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_params()


# --- mass, radii of gyration, trim pitch and wind profile (audit 0.7.19) ---------------------------

POWER = BASE.replace(**{"wind.profile": "power"})
LOG = BASE.replace(**{"wind.profile": "log"})


def _inertias(factor: float, base=BASE) -> dict:
    """The four moments of inertia times a factor (a whole file in g m^2 or t m^2)."""
    a = base.aerostat
    return {f"aerostat.{k}": getattr(a, k) * factor for k in ("Ixx", "Iyy", "Izz", "Ixz")}


#: (base, section, key, value, texts the ImplausibleParameterError must contain)
PROFILE_AND_MASS_REFUSED = [
    # 1 g for the 519 m^3 hull: 0.001 / (1.147 * 519 = 595.3 kg of air) = 1.68e-6 < 0.05
    (BASE, "aerostat", "mass", 0.001, ("aerostat.mass = 0.001 kg is 1.68e-06 of the 595.3 kg of "
                                       "air the hull displaces", "below 0.05")),
    # the baseline's 325.7 kg written in tonnes: 5.47e-4 of the displaced air
    (BASE, "aerostat", "mass", 0.3257, ("aerostat.mass = 0.3257 kg is 0.000547",
                                        "looks like tonnes written as kg")),
    # the winch at z = 0 and 300 m of tether: (300 / 10)^3 = 2.7e4 at the aerostat
    (POWER, "wind", "shear_exponent", 3.0, ("wind.shear_exponent = 3 exceeds 1 for wind.profile "
                                            "= 'power'", "2.7e+04-fold", "about 300 m")),
    (POWER, "wind", "shear_exponent", 14.0, ("wind.shear_exponent = 14 exceeds 1",
                                             "looks like a percentage written as a fraction")),
    # ln(300 / 9) / ln(10 / 9) = 3.5066 / 0.10536 = 33.28
    (LOG, "wind", "roughness_length", 9.0, ("wind.roughness_length = 9 m exceeds 5 m for "
                                            "wind.profile = 'log'", "33.3-fold",
                                            "looks like cm written as m")),
]


@pytest.mark.parametrize("base, section, key, value, texts", PROFILE_AND_MASS_REFUSED,
                         ids=[f"{c[2]}={c[3]!r}" for c in PROFILE_AND_MASS_REFUSED])
def test_mass_and_profile_slips_are_refused_in_a_file_and_as_overrides(tmp_path, base, section,
                                                                        key, value, texts):
    f = tmp_path / "slip.toml"
    f.write_text(_set_in_toml(dumps_toml(base), section, key, repr(value)))
    own = tmp_path / "own.toml"
    own.write_text(dumps_toml(base))
    for load in (lambda: load_params(f), lambda: load_params(own, {f"{section}.{key}": value})):
        with pytest.raises(ImplausibleParameterError) as err:
            load()
        for t in texts:
            assert t in str(err.value), str(err.value)


@pytest.mark.parametrize("over, texts", [
    # all four moments in g m^2: k_x = sqrt(3.135e6 / 325.7) = 98.11 m = 12.7 D (bound 2 D)
    (_inertias(1e3), ("aerostat.Ixx = 3.135e+06 kg m^2 gives a radius of gyration "
                      "sqrt(aerostat.Ixx / aerostat.mass) = 98.11 m, 12.7 x aerostat.diameter "
                      "= 7.7 m, outside [0.02, 2]", "looks like g m^2 written as kg m^2")),
    # in t m^2: k_x = sqrt(3.135 / 325.7) = 0.09811 m = 0.0127 D (bound 0.02 D)
    (_inertias(1e-3), ("aerostat.Ixx = 3.135 kg m^2", "= 0.09811 m, 0.0127 x aerostat.diameter",
                       "looks like t m^2 written as kg m^2")),
    # a body (|Izz - Ixx| <= Iyy <= Ixx + Izz) with k_x 0.80 D but k_y = sqrt(149740 / 325.7)
    # = 21.44 m = 1.17 L (bound 1 L)
    ({"aerostat.Ixx": 12540.0, "aerostat.Iyy": 149740.0, "aerostat.Izz": 149740.0},
     ("aerostat.Iyy = 149740 kg m^2", "= 21.44 m, 1.17 x aerostat.length = 18.3 m, outside "
                                      "[0.02, 1]")),
    # a needle: k_x = sqrt(20 / 325.7) = 0.032 D passes, k_y = sqrt(18.7 / 325.7) = 0.013 L
    ({"aerostat.Ixx": 20.0, "aerostat.Iyy": 18.7, "aerostat.Izz": 18.7, "aerostat.Ixz": 0.0},
     ("aerostat.Iyy = 18.7 kg m^2", "0.0131 x aerostat.length")),
])
def test_inertias_no_aerostat_has_are_refused(over, texts):
    with pytest.raises(ImplausibleParameterError) as err:
        load_params(overrides=over)
    for t in texts:
        assert t in str(err.value), str(err.value)


@pytest.mark.parametrize("over, texts", [
    # 100 / 595.3 = 0.168 < 0.25
    ({"aerostat.mass": 100.0}, ("aerostat.mass = 100 kg is 0.168 of the air",)),
    # k_x = 0.4029 * sqrt(10) = 1.27 D > 0.75 D, k_y = 0.262 * sqrt(10) = 0.829 L > 0.5 L
    (_inertias(10.0), ("aerostat.Ixx = 31350 kg m^2 gives a radius of gyration of 1.27 x "
                       "aerostat.diameter", "aerostat.Iyy = 74870 kg m^2 gives a radius of "
                       "gyration of 0.829 x aerostat.length")),
    # k_x = 0.4029 / sqrt(50) = 0.057 D < 0.1 D, k_z = 0.2552 / sqrt(50) = 0.0361 L < 0.06 L
    (_inertias(0.02), ("gyration of 0.057 x aerostat.diameter",
                       "aerostat.Izz = 142.06 kg m^2 gives a radius of gyration of 0.0361 x "
                       "aerostat.length")),
    ({"aerostat.trim_pitch_deg": 60.0}, ("aerostat.trim_pitch_deg = 60 deg (negative = nose up)",
                                         "outside [-20, 10] deg")),
    ({"aerostat.trim_pitch_deg": -30.0}, ("aerostat.trim_pitch_deg = -30 deg",)),
    # 30^0.6 = 7.70: the audit's 10 m/s at 10 m is 77 m/s at 300 m
    ({"wind.profile": "power", "wind.shear_exponent": 0.6},
     ("wind.shear_exponent = 0.6 is steeper", "7.7-fold")),
    # ln(300 / 3) / ln(10 / 3) = 4.605 / 1.204 = 3.825; 3 cm written as 3 m
    ({"wind.profile": "log", "wind.roughness_length": 3.0},
     ("wind.roughness_length = 3 m is rougher", "3.82-fold", "looks like cm written as m")),
])
def test_unusual_mass_inertia_pitch_and_profile_warn(over, texts):
    with pytest.warns(ParameterWarning) as record:
        load_params(overrides=over)
    text = " | ".join(str(w.message) for w in record)
    for t in texts:
        assert t in text, text


@pytest.mark.parametrize("over", [
    {"wind.profile": "power", "wind.shear_exponent": 0.5},  # the warning's edge (cities 0.4)
    {"wind.profile": "power", "wind.shear_exponent": 0.1},  # open sea
    {"wind.profile": "log", "wind.roughness_length": 2.0},  # the warning's edge (city centres)
    {"wind.profile": "log", "wind.roughness_length": 1e-5},  # calm sea
    {"wind.profile": "uniform", "wind.shear_exponent": 3.0,  # unused by the uniform profile
     "wind.roughness_length": 9.0},
    {"aerostat.trim_pitch_deg": -20.0}, {"aerostat.trim_pitch_deg": 10.0},
    {"aerostat.mass": 0.25 * 1.147 * 519.0 + 0.01},  # the mass warning's edge (148.8 kg)
    _inertias(0.1), _inertias(1.9),  # the ends of a +-90 % randomisation of the inertias
])
def test_real_mass_inertia_pitch_and_profiles_load_without_warnings(over):
    p = _load_quietly(overrides=over)
    for key, value in over.items():
        section, name = key.split(".")
        got = getattr(getattr(p, section), name)
        assert got == value if isinstance(value, str) else got == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize("p", [BASE, load_params("tcom_32m")]
                         + [scale_aerostat(BASE, f, 300.0, 5, -6.0) for f in (0.1, 10 ** -2.5, 10.0)],
                         ids=["baseline", "tcom_32m", "0.1x", "0.003x", "10x"])
def test_shipped_and_scaled_aerostats_sit_inside_the_mass_and_gyration_warnings(p):
    """Mass 0.547 of the displaced air (warning below 0.25, refused below 0.05); radii of
    gyration k_x 0.403 D (warning outside 0.1-0.75), k_y 0.262 L and k_z 0.255 L (0.06-0.5):
    geometric scaling (mass s^3, inertia s^5) keeps each ratio."""
    from aerostat_gym.params import gyration_radii, mass_ratio, plausibility_warnings

    assert mass_ratio(p) == pytest.approx(0.5471, abs=2e-4)
    radii = {key: k for key, _, k, *_ in gyration_radii(p)}
    assert radii == pytest.approx({"aerostat.Ixx": 0.4029, "aerostat.Iyy": 0.2620,
                                   "aerostat.Izz": 0.2552}, abs=2e-4)
    assert plausibility_warnings(p) == []


def test_the_env_refuses_a_profile_no_boundary_layer_has():
    """gym.make's overrides and a Params built by replace() meet the profile bounds (replace
    itself lets a study move past them, as for every plausibility bound)."""
    import gymnasium as gym

    import aerostat_gym  # noqa: F401  (registers the tasks)
    over = {"wind.profile": "power", "wind.shear_exponent": 3.0}
    assert BASE.replace(**over).wind.shear_exponent == 3.0
    for make in (lambda: gym.make("TetheredAerostat-v0", overrides=over),
                 lambda: gym.make("TetheredAerostat-v0", params=BASE.replace(**over))):
        with pytest.raises(ImplausibleParameterError, match=r"wind\.shear_exponent = 3 exceeds 1"):
            make()


def test_an_over_tension_in_a_sheared_wind_names_the_speed_at_the_aerostat():
    """The audit's case: 10 m/s at 10 m with alpha = 0.6 (a warning) breaks the tether at about
    80 m/s at the aerostat; the message names that speed, its height and the profile (it said
    only "at U = 10 m/s"). The speed is 10 (z / 10)^0.6 at the trimmed height z."""
    from aerostat_gym.analysis.trim import TrimLimitError, limit_warnings

    with pytest.warns(ParameterWarning, match="wind.shear_exponent = 0.6"):
        p = load_params(overrides={"wind.profile": "power", "wind.shear_exponent": 0.6})
    eq = find_equilibrium(p, 10.0)
    z = eq.summary["aerostat_position_m"][2]
    with pytest.raises(TrimLimitError) as err:
        limit_warnings(p, eq.summary)
    m = re.search(r"at U = 10 m/s at wind\.reference_height = 10 m \(([\d.]+) m/s at the "
                  r"aerostat's height of (\d+) m: wind\.profile = 'power', "
                  r"wind\.shear_exponent = 0\.6\) the trim tension \d+ N exceeds tether\.strength",
                  str(err.value))
    assert m, str(err.value)
    assert float(m.group(1)) == pytest.approx(10.0 * (z / 10.0) ** 0.6, rel=1e-3)
    assert float(m.group(1)) == pytest.approx(80.1, abs=0.5)
    assert float(m.group(2)) == pytest.approx(z, abs=0.5)


def test_a_stalled_trim_in_a_sheared_wind_names_the_speed_at_the_aerostat():
    """alpha = 1 (the refusal's edge, a warning) stalls the continuation near 5.2 m/s at 10 m,
    about 300 m/s at the stretched tether's top: the message names that speed (U z / 10 at the
    last equilibrium's height z) and the profile (it said only "at U = 5.188 m/s")."""
    with pytest.warns(ParameterWarning, match="wind.shear_exponent = 1 is steeper"):
        p = load_params(overrides={"wind.profile": "power", "wind.shear_exponent": 1.0})
    with pytest.raises(TrimError) as err:
        find_equilibrium(p, 10.0)
    m = re.search(r"no equilibrium found at U = ([\d.]+) m/s at wind\.reference_height = 10 m "
                  r"\(([\d.]+) m/s at the aerostat's height of (\d+) m: wind\.profile = 'power', "
                  r"wind\.shear_exponent = 1\) \(continuing from", str(err.value))
    assert m, str(err.value)
    u, v, z = (float(g) for g in m.groups())
    assert u == pytest.approx(5.19, abs=0.05)
    assert v == pytest.approx(u * z / 10.0, rel=2e-3)
    assert v > MAX_WIND_SPEED
