"""Parameters: strict loading, overrides, statuses and derived quantities."""

import math

import pytest

from aerostat_gym.params import (
    ParameterError,
    ParameterWarning,
    dumps_toml,
    load_params,
    parameter_table,
    params_from_dict,
    params_to_dict,
)

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib


@pytest.fixture(scope="module")
def base():
    return load_params()


def test_derived_quantities_match_reference_notes(base):
    """Derived values against docs/parameters.md (rel 1e-3): EA 1.0575e6 N, mu 0.02375 kg/m,
    b = zeta b_c = 161.6 N s, B - mg = 2645 N, m_e = 425.3 / 771.8 kg."""
    d = base.derived
    assert d.EA == pytest.approx(1.0575e6, rel=1e-3)
    assert d.mass_per_length == pytest.approx(0.02375, rel=1e-3)
    assert d.damping_b == pytest.approx(161.6, rel=1e-3)
    assert d.net_lift == pytest.approx(2645.0, rel=1e-3)
    assert d.effective_mass[0] == pytest.approx(425.3, rel=1e-3)
    assert d.effective_mass[2] == pytest.approx(771.8, rel=1e-3)


def test_leash_from_zero_wind_moment_balance(base):
    """x_l satisfies B (x_b cos th + z_b sin th) = (B - mg)(x_l cos th + z_l sin th) to 1e-12."""
    d, a = base.derived, base.aerostat
    th = math.radians(a.trim_pitch_deg)
    xb, _, zb = a.cb_position
    xl, _, zl = d.leash_position
    lhs = d.buoyancy * (xb * math.cos(th) + zb * math.sin(th))
    rhs = d.net_lift * (xl * math.cos(th) + zl * math.sin(th))
    assert lhs == pytest.approx(rhs, abs=1e-9 * d.buoyancy)


def test_every_value_has_a_status_and_unit(base):
    rows = parameter_table(base)
    assert len(rows) > 60
    for r in rows:
        assert r["status"] in {"SOURCED", "DERIVED", "ESTIMATE", "CALIB"}, r
        assert r["unit"], r


def test_round_trip_through_toml(base):
    assert params_from_dict(tomllib.loads(dumps_toml(base))) == base
    assert params_from_dict(params_to_dict(base)) == base


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("tether.length", -1.0, "tether.length must be > 0"),
        ("tether.diameter", 0.0, "tether.diameter must be > 0"),
        ("aerostat.volume", 0.0, "aerostat.volume must be > 0"),
        ("environment.rho_air", 0.0, "environment.rho_air must be > 0"),
        ("tether.n_elements", 0, "tether.n_elements must be an integer >= 1"),
        ("tether.n_elements", 2.5, "tether.n_elements must be an integer >= 1"),
        ("tether.n_elements", 6.0, r"got 6.0 \(write it without a decimal point\)"),
        ("tether.damping_ratio", -0.1, "tether.damping_ratio must be >= 0"),
        ("fins.alpha_stall_deg", 90.0, r"fins.alpha_stall_deg must lie in \(0, 90\)"),
        ("fins.alpha_stall_deg", 0.0, r"fins.alpha_stall_deg must lie in \(0, 90\)"),
        ("aerostat.k1", 50.0, r"aerostat.k1 must lie in \[0, 1\], got 50.0"),
        ("aerostat.k3", -0.1, r"aerostat.k3 must lie in \[0, 1\]"),
        ("hull.eta_k", 5.0, r"hull.eta_k must lie in \[0, 1\]"),
        ("fins.oswald_e", 1.2, r"fins.oswald_e must lie in \(0, 1\]"),
        ("fins.oswald_e", 0.0, r"fins.oswald_e must lie in \(0, 1\]"),
        ("hull.l_h", 500.0, r"hull.l_h = 500.0 m .* must not exceed aerostat.length = 18.3 m"),
        ("tether.length", "long", "tether.length must be a number"),
        ("tether.length", float("nan"), "tether.length must be finite"),
        ("wind.profile", "cubic", "wind.profile must be one of"),
        ("aerostat.mass", 1000.0, "gives no net lift"),
        # |Ixz| at and above sqrt(Ixx Izz) = sqrt(3135 * 7103) = 4718.89 kg m^2
        ("aerostat.Ixz", -30000.0, r"aerostat.Ixz = -30000.0 kg m\^2 makes the inertia tensor "
                                   r"indefinite: .* = 4718.9 kg m\^2"),
        ("aerostat.Ixz", 4718.9, "makes the inertia tensor indefinite"),
        # triangle inequalities: Iyy <= Ixx + Izz = 10238 and |Izz - Ixx| (Ixz small) <= Iyy
        ("aerostat.Iyy", 10300.0, r"aerostat.Iyy = 10300.0 kg m\^2 exceeds aerostat.Ixx \+ "
                                  r"aerostat.Izz = 3135.0 \+ 7103.0 = 10238.0 kg m\^2"),
        ("aerostat.Izz", 11000.0, r"aerostat.Ixx = 3135.0, aerostat.Izz = 11000.0 and aerostat.Ixz "
                                  r"= -300.0 kg m\^2 give x-z principal moments 7887.9 kg m\^2 "
                                  r"apart, more than aerostat.Iyy = 7487.0"),
        ("aerostat.cb_position", [1.0, 2.0], "must be a list of 3 numbers"),
        ("tether.colour", "red", "unknown parameter 'tether.colour'"),
        ("nonsense", 1, "unknown parameter 'nonsense'"),
        ("hull.cd_c", 0.2, r"unknown parameter 'hull.cd_c' \(did you mean 'hull.Cdc'\?\)"),
    ],
)
def test_invalid_values_name_the_field(base, key, value, message):
    with pytest.raises(ParameterError, match=message):
        base.replace(**{key: value})


def test_inertia_check_is_the_principal_moment_triangle(base):
    """The loader accepts an inertia tensor exactly when its principal moments (numpy's
    eigenvalues of [[Ixx, 0, -Ixz], [0, Iyy, 0], [-Ixz, 0, Izz]]) are positive and each is at
    most the sum of the other two, on 400 random tensors (about half of them refused) kept
    1e-6 away from the boundary; and a flat body (Izz = Ixx + Iyy, a plate) is accepted."""
    import numpy as np

    rng = np.random.default_rng(20261206)
    verdicts = []
    for _ in range(400):
        ixx, iyy, izz = rng.uniform(1000.0, 12000.0, 3)
        ixz = rng.uniform(-3000.0, 3000.0)
        lam = np.linalg.eigvalsh([[ixx, 0.0, -ixz], [0.0, iyy, 0.0], [-ixz, 0.0, izz]])
        margin = min(lam[0], lam[0] + lam[1] - lam[2]) / lam.sum()
        if abs(margin) < 1e-6:
            continue
        over = {"aerostat.Ixx": ixx, "aerostat.Iyy": iyy, "aerostat.Izz": izz, "aerostat.Ixz": ixz}
        try:
            base.replace(**over)
            accepted = True
        except ParameterError:
            accepted = False
        assert accepted == (margin > 0), over
        verdicts.append(accepted)
    assert 0.3 < np.mean(verdicts) < 0.7
    plate = base.replace(**{"aerostat.Ixz": 0.0, "aerostat.Izz": base.aerostat.Ixx
                            + base.aerostat.Iyy})
    assert plate.aerostat.Izz == pytest.approx(10622.0)


def test_unknown_key_missing_key_missing_section(base):
    data = params_to_dict(base)
    data["hull"]["mystery"] = 1.0
    with pytest.raises(ParameterError, match=r"unknown key\(s\) in \[hull\]: mystery$"):
        params_from_dict(data)
    data = params_to_dict(base)
    data["hull"]["cd_c"] = data["hull"].pop("Cdc")  # a typo names the key it was meant to be
    with pytest.raises(ParameterError, match=r"\[hull\]: cd_c \(did you mean 'Cdc'\?\)"):
        params_from_dict(data)
    data = params_to_dict(base)
    del data["tether"]["strength"]
    with pytest.raises(ParameterError, match=r"missing key\(s\) in \[tether\]: strength"):
        params_from_dict(data)
    data = params_to_dict(base)
    del data["winch"]
    with pytest.raises(ParameterError, match=r"missing section\(s\): winch"):
        params_from_dict(data)
    data = params_to_dict(base)
    data["extra"] = {}
    with pytest.raises(ParameterError, match=r"unknown section\(s\): extra$"):
        params_from_dict(data)
    data = params_to_dict(base)
    data["tethr"] = data.pop("tether")
    with pytest.raises(ParameterError, match=r"unknown section\(s\): tethr \(did you mean "
                                             r"'tether'\?\)"):
        params_from_dict(data)


def test_load_params_refuses_what_is_not_a_path(base):
    """A dict, a number or an already loaded Params is a ParameterError that says what
    load_params takes (and, for a dict, where to go), not os's TypeError."""
    with pytest.raises(ParameterError, match="got dict; for a dict of sections use params_from_dict"):
        load_params({"tether": {}})
    with pytest.raises(ParameterError, match="TOML path or a shipped configuration's name .* got float"):
        load_params(3.0)
    with pytest.raises(ParameterError, match="got a Params"):
        load_params(base)


def test_user_file_and_overrides(tmp_path, base):
    f = tmp_path / "mine.toml"
    f.write_text(dumps_toml(base).replace("length = 300.0", "length = 350.0"))
    p = load_params(f, overrides={"tether.n_elements": 20})
    assert p.tether.length == 350.0 and p.tether.n_elements == 20
    assert p.derived.element_length == pytest.approx(17.5)
    with pytest.raises(ParameterError, match="not found"):
        load_params(tmp_path / "absent.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[tether\nlength = 3")
    with pytest.raises(ParameterError, match="invalid TOML"):
        load_params(bad)


def test_packed_offsets_match_field_table():
    """The literal P_* offsets of the packed parameter vector equal the running sum of _FIELDS."""
    from aerostat_gym.physics import packing as layout

    off = 0
    for name, size in layout._FIELDS:
        assert getattr(layout, "P_" + name) == off, name
        off += size
    assert layout.P_SIZE == off


def test_a_file_that_is_not_utf8_is_named(tmp_path):
    """TOML is UTF-8: a Latin-1 comment is refused with the file, the byte and its offset (a
    bare UnicodeDecodeError named neither)."""
    path = tmp_path / "latin1.toml"
    path.write_bytes("# caf\u00e9\n".encode("latin-1"))
    with pytest.raises(ParameterError, match=rf"{path.name}: not UTF-8 text .* byte 0xe9 at offset 5"):
        load_params(path)


@pytest.mark.parametrize("key, value, message", [
    # V_h = 12 x 33.45 - 500 = -98.6 m^3: a negative volume ahead of the fins
    ("hull.I3", 500.0, r"puts -98.6 m\^3 of hull ahead of l_h .* outside \[0, aerostat.volume = 519\]"),
    # V_h = 401.4 + 300 = 701.4 m^3 > 519 m^3
    ("hull.I3", -300.0, r"puts 701.4 m\^3 of hull ahead of l_h"),
    # centroid 514.9 / 30 = 17.2 m, beyond l_h = 12 m
    ("hull.J1", 30.0, r"hull.J2 / hull.J1 = 17.16 m, the centroid .* outside the hull region"),
])
def test_hull_integrals_no_hull_can_have_warn_at_the_door(tmp_path, base, key, value, message):
    """The Jones-DeLaurier integrals are estimates, so an impossible set warns (naming the
    file, the fields and the volume or centroid they imply) rather than refusing; the shipped
    files are consistent (V_h = 424 m^3 of the baseline's 519, centroid 6.6 m of 12 m)."""
    path = tmp_path / "hull.toml"
    path.write_text(dumps_toml(base.replace(**{key: value})))
    with pytest.warns(ParameterWarning, match=message):
        load_params(path)
    assert base.hull.l_h * base.hull.I1 - base.hull.I3 == pytest.approx(424.13, abs=0.01)
