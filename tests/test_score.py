"""The winch-control score (the environment's default reward): the length term's free band,
each term against its formula on a known state, and the score ranking the classical baselines
like their pendulum damping. Every assertion states its tolerance."""

import numpy as np
import pytest

from aerostat_gym.agents.score_rank import (
    MIN_DAMPING_SPAN,
    rank_cells,
    rank_rows,
    summary,
)
from aerostat_gym.envs.kernel import C_LENGTH_BAND
from aerostat_gym.envs.reward import (
    DEFAULT_WEIGHTS,
    LENGTH_BAND_FRACTION,
    R_DISPLACEMENT,
    R_LENGTH,
    R_VELOCITY,
    REWARD_TERMS,
    reward_terms,
    weights_vector,
)
from aerostat_gym.envs.spaces import (
    N_OBS,
    OBS_DLENGTH,
    OBS_DPITCH,
    OBS_DX,
    OBS_DY,
    OBS_Q,
    OBS_VX,
    OBS_VY,
)
from aerostat_gym.envs.vector import TetheredAerostatVectorEnv
from aerostat_gym.params import load_params
from aerostat_gym.sim.events import DIVERGED, FIELD_END, RUNNING, TETHER_BREAK

BAND = LENGTH_BAND_FRACTION * 300.0 / 10.0  # the baseline's 15 m, in the 10 m channel scale


def _terms(dlength=0.0, dx=0.0, vx=0.0):
    obs = np.zeros(N_OBS, np.float32)
    obs[OBS_DLENGTH], obs[OBS_DX], obs[OBS_VX] = dlength, dx, vx
    terms = np.zeros(len(DEFAULT_WEIGHTS))
    reward_terms(obs, 0.0, 0.0, 0.0, RUNNING, weights_vector(None), 1.0e4, BAND, terms)
    return terms


def test_every_term_against_its_formula():
    """Each default term on a known state, by hand: dx, dy = 0.3, -0.4 (0.25); vx, vy = 0.6,
    0.8 (1.0); dpitch = 2 (4); q = -1 (1); a = 0.5 after -0.5; peak 1.5 x SWL; |dL| = 2.5
    against the 1.5 band (1.0); a tether break. Weights 1, 1, 0.1, 0.1, 0.01, 0.1, 10, 100, 1."""
    obs = np.zeros(N_OBS, np.float32)
    obs[[OBS_DX, OBS_DY, OBS_VX, OBS_VY, OBS_DPITCH, OBS_Q, OBS_DLENGTH]] = (
        0.3, -0.4, 0.6, 0.8, 2.0, -1.0, -2.5)
    terms = np.zeros(len(DEFAULT_WEIGHTS))
    reward_terms(obs, 0.5, -0.5, 1.5e4, TETHER_BREAK, weights_vector(None), 1.0e4, BAND, terms)
    expect = {"displacement": -0.25, "velocity": -1.0, "pitch": -0.4, "pitch_rate": -0.1,
              "effort": -0.0025, "effort_rate": -0.1, "over_tension": -5.0,
              "termination": -100.0, "length": -1.0}
    for name, value in expect.items():
        assert terms[REWARD_TERMS.index(name)] == pytest.approx(value, rel=1e-6), name
    for code, penalty in ((RUNNING, 0.0), (FIELD_END, 0.0), (DIVERGED, -100.0)):
        reward_terms(obs, 0.5, -0.5, 0.5e4, code, weights_vector(None), 1.0e4, BAND, terms)
        assert terms[REWARD_TERMS.index("termination")] == penalty
        assert terms[REWARD_TERMS.index("over_tension")] == 0.0  # below the SWL


def test_length_wander_is_free_inside_the_band():
    """|dL| up to 15 m (5 % of 300 m) costs nothing; 20 m costs w (0.5)^2 = 0.25 per step in the
    scaled channel (exact to float32), and the cost is even in dL."""
    assert _terms(dlength=1.4)[R_LENGTH] == 0.0
    assert _terms(dlength=-1.5)[R_LENGTH] == 0.0
    assert _terms(dlength=2.0)[R_LENGTH] == pytest.approx(-0.25, rel=1e-6)
    assert _terms(dlength=-2.0)[R_LENGTH] == pytest.approx(-0.25, rel=1e-6)


def test_swing_displacement_and_velocity_weigh_alike():
    """A 10 m displacement (1 in the scaled channel) and a 2 m/s velocity (1 scaled) cost the
    same, 1.0 each with the default weights (exact to float32)."""
    assert _terms(dx=1.0)[R_DISPLACEMENT] == pytest.approx(-1.0, rel=1e-6)
    assert _terms(vx=1.0)[R_VELOCITY] == pytest.approx(-1.0, rel=1e-6)


def test_environment_applies_the_band_of_its_tether():
    """The env's length band follows its tether length: 5 % of 200 m = 10 m = 1.0 scaled."""
    env = TetheredAerostatVectorEnv(num_envs=1, tether_length=200.0, turbulence="none")
    assert env.batch.cfg[C_LENGTH_BAND] == pytest.approx(1.0, rel=1e-12)
    env.close()


def test_score_ranks_the_baselines_like_their_damping():
    """Recover (10 m along-wind swing), 10 and 15 m/s, the five baselines: the episode returns
    order exactly as the fitted pendulum damping ratios (Spearman 1.0 in both cells, measured
    when written), and the modal controller is first in both."""
    cells = rank_cells(rank_rows(load_params(), scenarios=["recover"], speeds=(10.0, 15.0)))
    for c in cells:
        assert c["rho"] == pytest.approx(1.0, abs=1e-12), c
        assert c["best_agrees"] and c["policies"][int(np.argmax(c["returns"]))] == "modal"
    s = summary(cells)
    assert s["ranked_cells"] == 2 and s["mean_rho_ranked"] == pytest.approx(1.0, abs=1e-12)


def test_summary_leaves_out_cells_without_a_ranking():
    """A cell whose damping ratios span less than MIN_DAMPING_SPAN counts in the overall mean
    but not in the ranked one (constructed cells: rho 1.0 and 0.0)."""
    cells = [{"rho": 1.0, "zetas": [0.1, 0.2, 0.3], "best_agrees": True},
             {"rho": 0.0, "zetas": [0.1, 0.1 + MIN_DAMPING_SPAN / 2], "best_agrees": False}]
    s = summary(cells)
    assert s["mean_rho"] == pytest.approx(0.5) and s["mean_rho_ranked"] == pytest.approx(1.0)
    assert (s["ranked_cells"], s["best_agrees"]) == (1, 1)
