"""``TetheredAerostat-v0``: the single Gymnasium environment (a thin adapter over
:class:`aerostat_gym.envs.batch.EnvBatch` with one slot)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
from gymnasium.error import ResetNeeded

from ..sim.events import FAILURES, FIELD_END, OUTCOMES, RUNNING
from . import reward
from .batch import EnvBatch
from .config import TaskConfig, TaskError
from .render import RENDER_MODES, Frame, Renderer


def frame(s: dict):
    """The renderer's Frame from an :meth:`EnvBatch.snapshot` (the episode's mean wind)."""
    d = math.radians(s["params"].wind.direction_deg)
    wind = s["wind_speed"] * np.array([math.cos(d), math.sin(d), 0.0])
    return Frame(time=s["time"], nodes=s["nodes"], cm_pos=s["cm_pos"], euler=s["euler"],
                 wind=wind, tension=s["tension"],
                 length=s["length"], reel_speed=s["reel_speed"], trim_cm=s["trim_cm"])


class TetheredAerostatEnv(gym.Env):
    """
    ## Description

    A streamlined aerostat (Aeros Flightcam class, 519 m^3) flies on a 300 m viscoelastic
    tether from a ground winch, after Lambert and Nahon, "Stability Analysis of a Tethered
    Aerostat" (AIAA 2002-4497): a lumped-mass tether of n elements (Morison drag, gravity,
    tension-only viscoelastic elements) joined at the confluence point to a rigid 6-DOF
    aerostat modelled by component breakdown, in a mean wind with turbulence. The task is to
    damp the aerostat's pendulum (blow-by) and pitch oscillations with the winch alone.

    Frames and signs: inertial X, Y, Z with Z up and the winch at the origin; the mean wind
    blows along +X, so at trim the aerostat flies downwind (X > 0) with its nose into the wind
    (yaw psi = pi). Attitude is the Z-Y-X Euler triple (roll phi, pitch theta, yaw psi;
    theta < 0 is nose up, so a positive pitch observation is nose down); body rates p, q, r
    about the body x (nose), y, z axes. A positive reel speed
    pays line out. SI units throughout.

    ## Action Space

    ``Box(-1, 1, (1,), float32)``: the winch reel-speed set-point as a fraction of the winch's
    maximum speed (``winch.max_speed``, 1 m/s by default); positive pays out. The winch's
    speed loop (time constant, acceleration and motor-force limits) follows the set-point;
    the brake engages on an exact-zero set-point (so action 0 is the passive, braked winch) or
    once the set-point has stayed below ``winch.brake_speed`` (0.002 m/s) for
    ``winch.brake_dwell`` (10 s), and clamps the drum once it has slowed down. Over-hauled (the tether tension
    above the motor's force limit, ``winch.max_motor_force``, from about 27 m/s with the
    baseline), the winch sets its holding brake against reel-in and hold commands and pays out
    no faster than ``winch.max_speed`` on pay-out commands. Out-of-range actions are clipped
    to [-1, 1] (counted in ``info["action_clipped"]``). Accepted: a real number, or a list,
    tuple or array of real numbers of shape (1,) or (1, 1); a NaN or infinite action, a
    string, None, a boolean, a complex number or another shape raises
    :class:`aerostat_gym.envs.ActionError` naming what was given.

    ## Observation Space

    ``Box(low, high, (19,), float32)`` with ``observation="standard"``: each channel is a
    physical quantity divided by its scale, clipped to finite bounds
    (:func:`aerostat_gym.envs.observation_table` prints the table):

    | index | quantity | unit | scale |
    |---|---|---|---|
    | 0-2 | aerostat CM position minus the episode's trim (X, Y, Z) | m | 10 |
    | 3-5 | aerostat CM velocity (X, Y, Z) | m/s | 2 |
    | 6-8 | roll, pitch, yaw minus trim (yaw wrapped to [-pi, pi]; pitch > 0 nose down) | rad | 0.05 |
    | 9-11 | body rates p, q, r | rad/s | 0.02 |
    | 12 | winch tension (load cell) | N | 1e4 |
    | 13 | winch tension minus its trim value | N | 1e3 |
    | 14 | tether length minus trim | m | 10 |
    | 15 | reel speed | m/s | 1 |
    | 16-18 | measured air velocity at the aerostat CM (X, Y, Z) | m/s | 10 |

    ``obs_noise`` adds Gaussian noise of that standard deviation (in scaled units) to these
    channels. ``observation="full"`` appends, unscaled and privileged, the episode's mean
    wind speed [m/s] and the full simulator state minus trim (6 n + 8 entries in
    :class:`aerostat_gym.physics.state.StateLayout` order; 68 for n = 10): 88 channels.

    ## Rewards

    The reward is the winch-control score (:mod:`aerostat_gym.envs.reward`; the evaluator's
    suite score is the mean episode return): the sum of named non-positive terms, each in
    ``info["reward_<name>"]`` (so ``reward == sum`` of them to float precision), with weights
    from ``reward_weights``: displacement ``-w (dx^2+dy^2)`` and velocity ``-w (vx^2+vy^2)`` in
    the scaled channels above (horizontal: the blow-by swing; the winch's own reeling moves the
    aerostat vertically); pitch ``-w dpitch^2``; pitch_rate ``-w q^2``; effort ``-w a^2``;
    effort_rate ``-w (a - a_prev)^2``; over_tension ``-w max(0, T_peak / SWL - 1)`` with the
    peak element tension over the step and the winch's safe working load; termination ``-w``
    on a terminating step; length ``-w max(0, |dlength| - band)^2`` (channel 14, band 5 % of
    the tether length: the length may wander 15 m for free on the baseline). Defaults:
    ``aerostat_gym.envs.DEFAULT_WEIGHTS``, for the 300 m reference tether: on a tether k times
    as long the displacement and length weights are divided by k^2 and the velocity weight by
    k (``aerostat_gym.envs.reward.sized_weights``: a swing through the same angle scores the
    same; ``reward_table(tether_length=L)`` lists the weights applied).

    The reward is swappable (:mod:`aerostat_gym.envs.reward`): ``reward_fn=f`` replaces it by
    ``f(obs, action, info)``, called after each step with the new observation, the applied
    action and the step's info (which keeps the default terms and ``info["peak_tension"]``).

    ## Starting State

    The exact trim (equilibrium) for a mean wind speed drawn uniformly among the points of the
    0.1 m/s grid inside ``wind_speed`` (default 3 to 15 m/s; a single number is taken exactly,
    on the grid or off it), then perturbed (``perturbation``, default
    ``"mixed"``): aerostat and tether swung rigidly about the winch by up to 10 m along the
    wind and 5 m across it (no element stretched), the aerostat pitched about its confluence
    point by up to 0.05 rad, and with probability 0.5 a 1 - cos gust along the wind (1-4 m/s,
    5-20 s, onset within 30 s). Turbulence (default ``"moderate"``: sigma_u / U(h) = 10 % at
    the aerostat, MIL-F-8785C low-altitude model with W20 from the mean profile, von Karman)
    is a frozen coherent field from a bank of unit-variance fields generated once per process
    from ``wind_bank_seed``; each episode reads a random bank field from a random along-wind
    offset, scaled to that episode's mean wind.
    ``reset(options={"wind_speed": U, "perturbation": ...})`` fixes them for one episode (U
    exactly, anywhere in the task's range: off the grid the trim is computed at the reset, a
    few ms). ``reset(options={"snapshot": s})`` with ``s`` from :meth:`get_state` (of this env
    or one made with the same arguments) restores it as :meth:`set_state` does, through the
    wrappers' reset: the way to restore into an environment made by ``gym.make`` that was
    never reset (Gymnasium's order check refuses a step after ``env.unwrapped.set_state``
    there).

    ## Episode End

    Terminated on tether break (an element above the tether strength), ground strike (the
    aerostat CM below one hull diameter), tether length outside the winch's limits, or
    numerical failure (``info["failure"]``: ``"nonfinite_state"``, ``"nonfinite_output"`` or
    ``"numerical_divergence"``, a finite state beyond every physical bound, see
    :func:`aerostat_gym.sim.events.diverged`; the observation is that of the last good state;
    no exception). A break, strike or limit is re-run with finer integration steps before it
    ends the episode: one they do not reproduce goes on from their state
    (:func:`aerostat_gym.sim.resolve.resolve`). ``info["termination"]`` names the reason.
    Truncated by the time limit set at
    registration (600 steps = 120 s at the default 0.2 s control step) or passed to
    ``gym.make(..., max_episode_steps=N)``: the turbulence fields are periodic and read modulo
    their length, so episodes of any length are served.

    ## Arguments

    ``gym.make("TetheredAerostat-v0", **kwargs)`` with:

    - ``wind_speed=(3.0, 15.0)``: range of the episode's mean wind speed [m/s], drawn among the
      0.1 m/s grid points inside it (a range holding none, such as ``(3.01, 3.04)``, is a
      ``TaskError``); a single number fixes it exactly (``wind_speed=10.05`` is
      ``(10.05, 10.05)``; the same holds for the gust ranges).
    - ``turbulence="moderate"``: intensity class ("none", "light", "moderate", "severe":
      sigma follows each episode's mean wind, :mod:`aerostat_gym.wind.presets`), "config" (the
      parameter file's ``wind.turbulence`` and ``wind.turbulence_model``), or a dict of
      :class:`aerostat_gym.wind.TurbulenceConfig` fields (key "preset" picks the base;
      explicit sigma_u / sigma_v / sigma_w give a fixed, measured-site intensity). The field's
      heights run from the winch to above the highest point the aerostat reaches at
      ``winch.max_length`` and its extent follows the longest tether
      (:func:`aerostat_gym.wind.sizing.field_extent`); ``wind.turbulence_reference_height``
      sets the advection height.
    - ``turbulence_mix=None``: a per-episode draw of the intensity class, ``{class: weight}``
      (e.g. ``{"none": 0.5, "light": 0.25, "moderate": 0.25}``); each episode reads the bank at
      its drawn class's sigma (``info["turbulence_class"]``), the rest of the episode as
      without the mix. ``turbulence`` must then be a wind-scaled class other than "none": the
      fields keep its length scales, which the classes share.
    - ``perturbation="mixed"``: "none", "displacement", "gust", "mixed" or a dict with keys
      swing [m], lateral [m], pitch [rad], gust_probability, gust_amplitude [m/s] (low, high),
      gust_duration [s] (low, high), gust_onset [s] (low, high). A preset's swing and lateral
      displacement are stated for a 300 m tether and scale with the configured one (the same
      swing angle on every aerostat; ``aerostat_gym.envs.spaces.displacement_scale``); a
      dict's are taken in metres.
    - ``tether_length=None`` [m] and ``n_elements=None``: override the parameter file.
    - ``integrator="semi-implicit"`` or ``"rk4"`` (the reference; about 7x slower).
    - ``control_step=0.2`` [s]: 220 steps per pendulum period (~44 s), ~15 per axial-spring
      period (2.9 s), while the winch's 0.3 s speed loop and 0.5 m/s^2 acceleration limit make
      faster commands pointless; 600 steps per 120 s episode keep the credit-assignment horizon
      of RL within reach (gamma = 0.99 looks ~20 s ahead). The episode length in steps is the
      registration's ``max_episode_steps``: pass ``max_episode_steps`` to ``gym.make`` with a
      different control step.
    - ``params=None``: a :class:`aerostat_gym.params.Params` or a TOML path (default: the
      shipped baseline); ``overrides``: {"section.key": value}.
    - ``randomize=None``: domain randomisation, {"section.key": relative half-range} or True for
      the estimated parameters in ``aerostat_gym.envs.config.DEFAULT_RANDOMIZATION``; each
      episode re-trims for its drawn parameters (a few ms per reset). Draws are independent
      and uniform; moments of inertia no body has (a broken triangle inequality, about 11 % of
      the default draws) are drawn again, and inertia ranges that give bodies less than 5 % of
      the time are refused here.
    - ``weathercock=False``: with ``randomize``, an aerostat that does not weathervane at its
      episode's trim (its static yaw moment not restoring at every yaw offset of
      ``aerostat_gym.analysis.directional.WEATHERCOCK_OFFSETS_DEG``, 2.5-10 deg) is drawn
      again; refused here where under 5 % of the draws weathervane.
      ``TetheredAerostatRealisticWeathervaning-v0`` sets it (0.7.22; v0 draws about 15 % that
      do not, and they hold most of its heavy tail: docs/parameters.md 5.5).
    - ``obs_noise=0.0``: sensor noise std in scaled units. ``reward_weights=None``: dict of
      weights by term name. ``reward_fn=None``: a user reward ``f(obs, action, info) -> float``.
      ``observation="standard"`` or ``"full"``.
    - ``wind_bank_size=8``, ``wind_bank_seed=0``: the shared turbulence bank.
    - ``render_mode=None``: "rgb_array" (an (480, 800, 3) frame: side view x-z with the tether,
      hull, fins, wind arrow and tension readout, plus a top view x-y) or "human".

    ## Version History

    - v0: initial release (aerostat-gym 0.1).
    - v0 (aerostat-gym 0.2), unchanged dynamics, observation and reward: ``reward_fn``
      argument, ``info["peak_tension"]``, ``get_state`` / ``set_state``; the pitch channel's
      documented sign corrected (positive is nose down, as it always was).
    - v0 (aerostat-gym 0.2; dynamics changed, id kept as the package's public name): turbulence
      classes scale with each episode's mean wind (MIL-F-8785C, TI 5 / 10 / 15 % at 300 m, was
      fixed sigma_u 0.8 / 1.6 / 2.4 m/s); fins with Viterna-Corrigan post-stall normal force
      beyond a 45 deg stall (was C_L flat beyond 16 deg); the turbulence field sized from the
      configuration (430 m high for the baseline, was 340 m); an optional Froude-Krylov plus
      added-mass force of accelerating air on the hull (``aerostat.air_inertia``, off by
      default). Steady-wind trims are unchanged.
    - v0 (aerostat-gym 0.3; reward and winch logic changed, id kept): the default reward is the
      winch-control score (displacement weight 1.0, was 0.2; the length term free within 5 % of
      the tether length, was quadratic from zero), so returns are not comparable with 0.2's; the
      winch brakes on an exact-zero command or after ``winch.brake_dwell`` = 10 s inside
      ``winch.brake_speed`` = 0.002 m/s (was: at once below 0.02 m/s), so small commands reach
      the drum; the stand-still clock is part of ``get_state``. Trims and the braked dynamics
      are unchanged. New task id ``TetheredAerostatDampingNoisy-v0`` (the damping task with the
      evaluation protocol's sensor noise, 0.01), the shipped policy's task.
    - v0 (aerostat-gym 0.4; dynamics, observation and reward unchanged): new task id
      ``TetheredAerostatRealistic-v0`` (light turbulence, swing perturbations, randomised
      estimated parameters, sensor noise 0.01), the shipped policy's task.
    - v0 (aerostat-gym 0.5; dynamics, observation and reward unchanged, every 0.4 evaluation
      reproduced): ``obs_noise`` is refused unless a finite real number >= 0 (``True`` was taken
      as 1.0).
    - v0 (aerostat-gym 0.6; dynamics, observation and reward unchanged): ``turbulence_mix``, a
      per-episode intensity-class draw (absent, every episode is as in 0.5).
    - v0 (aerostat-gym 0.7.2; dynamics, observation and reward unchanged): an unknown argument
      is a ``TaskError`` naming it and the nearest accepted one (was a ``TypeError``).
    - v0 (aerostat-gym 0.7.3; every 0.4 evaluation and the baseline's observation space
      unchanged): a terminating step that half the integration step does not reproduce is
      re-integrated at finer steps and, if they show no event, the episode goes on from their
      state (was: ``numerical_divergence``); an over-hauled winch drum paying out stops at
      ``winch.max_length`` (was: ran past it, ending the episode on the length limit); the
      clip limits of the position, length and tension channels grow with the configured
      winch's reach and tether's strength (were the baseline's 400 m, 250 m and 100 kN).
    - v0 (aerostat-gym 0.7.5; the registered tasks, the baseline and every evaluation
      unchanged): ``integrator="rk4"`` takes the tether's axial stability bound capped at
      ``simulation.semi_implicit_dt`` (was the axial bound alone, which on a few long elements
      under a small hull let the aerodynamics go unstable; the baseline's axial bound, 5.8 ms,
      is the smaller); ``wind_speed`` and the gust ranges accept a single number, the fixed
      value (was a ``TaskError``); a reset option ``wind_speed`` that is not a number is a
      ``TaskError`` quoting it.
    - v0 (aerostat-gym 0.7.6; the integration, observation and reward unchanged where no
      event is near): a step's ``info["peak_tension"]`` includes its end state (was counted at the
      start of the next step); a semi-implicit tether break that half the step does not
      reproduce within 10 % (a slack element snapping taut within one step) is re-integrated
      until the finer steps agree (was ``numerical_divergence``: on 55 m of tether in 24
      elements in severe turbulence, 0 failures where there were 13-55 per 9,600 steps); the
      wind range's trims are judged by the tether's largest tension (was the winch end); the
      vector env supports ``autoreset_mode=AutoresetMode.DISABLED``, checks ``reset_mask`` and
      refuses a ``max_episode_steps`` below 1 (0 meant 600, a negative one truncated every step).
    - v0 (aerostat-gym 0.7.7; dynamics, observation and reward unchanged): the doors read
      numbers by one rule (a bool is never a count, a NumPy integer is one: ``num_envs=
      np.int64(4)`` is accepted, ``num_envs=True`` refused); ``wind_bank_seed`` must be an
      integer >= 0 (a NumPy TypeError before); ``overrides``, ``reward_weights`` and the reset
      options must be mappings (TypeErrors before); ``wind_speed`` is capped at 100 m/s, where
      the incompressible aerodynamics end (1e300 hung the trim table).
    - v0 (aerostat-gym 0.7.10; the registered tasks on the baseline's 300 m tether, the
      dynamics, observation and reward unchanged): a perturbation preset's swing and lateral
      displacement scale with the configured tether's length over 300 m (were 10 m and 5 m on
      every tether: 10 deg of swing on a 60 m tether); a dict is still taken in metres; the
      default reward's displacement, length and velocity weights are divided by k^2, k^2 and k,
      k = L / 300 m (were the baseline's on every tether, so a 60 m aerostat's swing weighed
      25 times less against its pitch and effort terms than the baseline's).
    - v0 (aerostat-gym 0.7.12; dynamics, observation and reward unchanged; what a randomised
      episode draws changed): ``randomize`` draws again the moments of inertia no body has (a
      broken triangle inequality, about 11 % of the default draws; were kept), and inertia
      ranges whose draws are bodies less than 5 % of the time are a ``TaskError``. A seeded
      start whose first draw is a body is bit-identical (19 of the 20 return seeds of
      ``TetheredAerostatRealistic-v0``; seed 1001 draws again); a stream of unseeded resets
      differs from its first redraw on. Unrandomised tasks are bit-identical.
    - v0 (aerostat-gym 0.7.13; the registered tasks, their seeded episodes and every stored
      evaluation unchanged): the episode's wind speed is the one asked for: a single
      ``wind_speed`` or a reset option off the 0.1 m/s grid is trimmed exactly (was moved to
      the grid: 10.05 gave 10.0 at make and 10.1 as a reset option, 0.05 gave 0.0), a reset
      option outside the range is refused (was accepted within 0.05 m/s of its ends), a range
      draws among the grid points inside it (was rounded: (3.01, 3.04) drew 3.0) and a range
      with none is a ``TaskError``; ``step()`` before ``reset()`` raises
      ``gymnasium.error.ResetNeeded`` (was a ``nonfinite_state`` failure), ``render()`` before
      it too (an AttributeError), and every call but ``close()`` after ``close()`` raises
      ``gymnasium.error.ClosedEnvironmentError`` (ran on in calm air); the perturbation's
      fields are bounded (swing and lateral by the tether length, pitch by pi/2, gust
      amplitude plus the top mean wind by 100 m/s, duration in (0, 3600] s, onset by
      86400 s) and a turbulence bank above 4 GiB (``aerostat_gym.wind.synthesis.MAX_FIELD_BYTES``) is a ``TaskError`` at make
      (was a NumPy MemoryError); the native vector env's infos are ``SyncVectorEnv``'s (plain
      reset keys, ``final_info``, ``time``; no ``truncation`` reason at a time limit). With
      the winch off the origin (``tether.anchor_position``) the start's swing pivots on the
      winch (it pivoted on the origin, which stretched the tether and broke it on the first
      step); with the winch at the origin, as in every registered task, starts are unchanged.
    - v0 (aerostat-gym 0.7.14; the registered tasks, their seeded episodes and every stored
      evaluation unchanged): ``overrides`` and a ``params`` built with ``Params.replace`` meet
      the loader's plausibility bounds at make (``ImplausibleParameterError``; were accepted:
      an RK4 step past its stability bound, a tether density in g/cm^3); an aerostat whose
      net lift only just exceeds its tether's weight trims in light wind (failed after 6-24 s
      at 0.5-3 m/s), and a trim that would hang the tether below the ground is refused naming
      the weights; an off-grid reset speed's trim is remembered by the environment.
    - v0 (aerostat-gym 0.7.15; dynamics, observation, reward, the registered tasks and their
      seeded episodes unchanged): more is refused at make, each naming the value: a ``params``
      rebuilt with ``dataclasses.replace`` meets the loader's field and cross checks; a log
      wind profile with its roughness at or above its reference height; values no aerostat
      has (``params.PLAUSIBLE_RANGES``: g, air density, tether damping, hull and fin drag, fin
      lift slope); randomisation ranges whose ends are implausible; ``num_envs`` above 65,536;
      ``control_step`` below 1 ms; a ``reward_fn`` that does not take (obs, action, info), or
      returns a string or a bool. A 0-d array or NumPy scalar is a number. ``set_state``
      leaves the env unchanged when it refuses a snapshot. ``step()`` after the episode ended
      (terminated, or truncated by the end of the wind field) raises
      ``gymnasium.error.ResetNeeded`` naming the reason (it went on integrating the broken
      system, -100 a step).
    - v0 (aerostat-gym 0.7.16; dynamics, observation, reward, the registered tasks and their
      seeded episodes unchanged): a ``get_state`` snapshot carries what the environment, not
      the simulator slot, adds to its future (``world``: turbulence fields, control step,
      ground, winch and reward settings, observation bounds and noise), and ``set_state``
      refuses one whose world differs, naming what differs (a snapshot from another tether
      length with the same element count ran on with this env's reward band). Arguments
      that resolve alike are the same world; another integration step or integrator is
      allowed (a re-run); snapshots of 0.7.15 and before are taken on trust.
    - v0 (aerostat-gym 0.7.17; reward, calm-air dynamics and episodes and the baseline's
      observation space unchanged): the turbulence has its class's sigma between the field's
      height rows, where the aerostat flies (the linear interpolation between partly
      correlated rows lost 3 / 5 / 8 % of sigma in u / v / w there), so turbulent episodes
      differ from 0.7.16's. On another aerostat the reel-speed
      channel's limit is twice ``winch.max_speed`` (it clipped at 2 m/s on a faster winch) and
      the body rates' 2 rad/s x sqrt(18.3 m / hull length) on a shorter hull; a snapshot's
      world read back from JSON or YAML is the same world. ``reset(options={"snapshot": s})``
      restores a snapshot through the wrappers' reset; ``set_state`` with the snapshot of an
      ended episode keeps it ended (it reopened ``step``), refuses a snapshot whose episode is
      not an ``Episode``, and ``get_state`` and ``render`` after ``close`` raise
      ``ClosedEnvironmentError``. The vector env's ``render()`` returns one frame per
      environment (environment 0's before); the SB3 adapter's per-environment infos are
      ``DummyVecEnv``'s at every step (empty but at an episode's end before), its
      ``get_images`` returns the frames, and it refuses ``env_method`` (which called the whole
      batch's method once per index) and ``set_attr`` on some environments only.
    - v0 (aerostat-gym 0.7.18; dynamics, observation, reward and episodes unchanged): a
      turbulent env whose ``tether_length`` (or ``tether.length`` override) leaves the
      turbulence reference height a factor 1.5 off warns (``ParameterWarning``), as loading
      such a file does, at the caller's line (past gymnasium's frames under ``gym.make``).
    - v0 (aerostat-gym 0.7.22; dynamics, observation, reward and the seeded episodes of every
      task registered before unchanged): the argument ``weathercock`` (default False) and the
      task ``TetheredAerostatRealisticWeathervaning-v0``, which sets it; at make, values no
      aerostat has are refused (a mass below 0.05 of the displaced air, radii of gyration
      outside 0.02-2 D or 0.02-1 L, a power-law shear exponent above 1, a log roughness
      length above 5 m).
    """

    metadata = {"render_modes": list(RENDER_MODES), "render_fps": 5}
    #: an episode runs and the env is open, so step() may go on: set by reset() and
    #: set_state(), cleared by close() (a class default: also for instances made before it)
    _ready = False
    #: the reason the last episode ended (terminated or truncated by the env), until a reset
    _ended: str | None = None

    def __init__(self, render_mode: str | None = None, **kwargs):
        if render_mode is not None and render_mode not in RENDER_MODES:
            raise ValueError(f"unknown render_mode {render_mode!r}; choose one of {RENDER_MODES}")
        self.render_mode = render_mode
        self.task = TaskConfig.from_kwargs(**kwargs)
        self._batch = EnvBatch(self.task, 1)
        b = self._batch
        self.action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
        self.observation_space = gym.spaces.Box(b.obs_low, b.obs_high, dtype=np.float32)
        self.metadata = {**self.metadata, "render_fps": round(1.0 / self.task.control_step)}
        self._renderer = None

    # --- Gymnasium API ---------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        self._batch.check_open("reset()")
        if isinstance(options, dict) and "snapshot" in options:
            return self._restore(seed, options)
        super().reset(seed=seed)
        info = self._batch.reset_one(0, self.np_random, options)
        self._batch.add_noise(0, self.np_random)
        self._ready, self._ended = True, None
        if self.render_mode == "human":
            self.render()
        return self._batch.obs[0].copy(), info

    def _restore(self, seed, options: dict):
        """``reset(options={"snapshot": get_state()})``: :meth:`set_state` through the
        wrappers' own reset (Gymnasium's order check and environment checker see a reset, the
        TimeLimit wrapper counts its steps from here); the reset info is the episode's."""
        saved = options["snapshot"]
        if seed is not None or len(options) > 1:
            raise TaskError("the reset option 'snapshot' restores a get_state() snapshot with "
                            "its own random generator: it takes no seed and no other option")
        if isinstance(saved, dict) and saved.get("code", RUNNING) != RUNNING:
            raise TaskError(f"the snapshot's episode has ended ({OUTCOMES[int(saved['code'])]}):"
                            " there is nothing to step from it; reset() starts a new one")
        obs = self.set_state(saved)
        return obs, dict(self.episode.info)

    def step(self, action):
        b = self._batch
        if not self._ready:  # one flag per step; the reason is worked out only when it fails
            if self._ended is not None:  # a broken tether or a spent wind field goes no further
                raise ResetNeeded(f"step() after the episode ended ({self._ended}): call "
                                  "reset() to start a new one")
            b.check_started("step()")
        clipped = b.set_actions(action)
        b.step()
        b.add_noise(0, self.np_random)
        terms = b.terms[0]
        code = int(b.code[0])
        info = {"reward_" + k: terms[j] for j, k in enumerate(reward.REWARD_TERMS)}
        info["action_clipped"] = bool(clipped[0])
        info["time"] = b.time[0]
        info["peak_tension"] = b.peak[0]
        terminated = truncated = False
        if code != RUNNING:
            reason = OUTCOMES[code]
            if code == FIELD_END:
                truncated = True
                info["truncation"] = reason
            else:
                terminated = True
                info["termination"] = reason
                if code in FAILURES:
                    info["failure"] = reason
            self._ready, self._ended = False, reason
        if self.render_mode == "human":
            self.render()
        obs = b.obs[0].copy()
        fn = self.task.reward_fn
        r = float(terms.sum()) if fn is None else reward.custom_reward(fn, obs, b.action[0], info)
        return obs, r, terminated, truncated, info

    def render(self):
        self._batch.check_open("render()")
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode="
                            "'rgb_array' or 'human' to gym.make")
            return None
        self._batch.check_started("render()")
        if self._renderer is None:
            self._renderer = Renderer(self._batch.params, self.render_mode,
                                      fps=self.metadata["render_fps"])
        return self._renderer.render(frame(self._batch.snapshot(0)))

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self._batch.release()
        self._ready = False

    # --- helpers ---------------------------------------------------------------------------

    @property
    def state(self) -> np.ndarray:
        """The full simulator state (copy; StateLayout order)."""
        return self._batch.state[0].copy()

    def get_state(self) -> dict:
        """Everything that determines the rest of the episode: the simulator slot (state,
        trim, packed parameters, wind, clock, winch brake and last action), the last
        observation, the random generator's state (observation noise) and what the
        environment adds to the slot's future (``world``: turbulence fields, control step,
        ground, winch and reward settings, observation bounds). Pass it to :meth:`set_state` of
        this environment, or of one made with the same arguments, to return here: the steps
        that follow are bit-identical."""
        self._batch.check_open("get_state()")
        saved = self._batch.get_slot(0)
        saved["np_random"] = self.np_random.bit_generator.state
        return saved

    def set_state(self, saved: dict) -> np.ndarray:
        """Restore a :meth:`get_state` snapshot; returns the observation saved with it. A
        snapshot of an environment with another world (see :meth:`get_state`) is refused,
        naming what differs, and leaves this one as it was; one taken on another integration
        step or with the other integrator is accepted (a re-run of the same state)."""
        self._batch.check_open("set_state()")
        if not isinstance(saved, dict) or "np_random" not in saved:
            raise ValueError("set_state expects a dict from get_state()")
        generator = type(self.np_random.bit_generator)()
        try:  # checked on a spare generator first: a refused snapshot leaves the env as it was
            generator.state = saved["np_random"]
        except (TypeError, ValueError, KeyError) as exc:
            raise ValueError(f"set_state: np_random is not a {type(generator).__name__} state "
                             f"from get_state() ({exc})") from None
        self._batch.set_slot(0, saved)
        self.np_random.bit_generator.state = saved["np_random"]
        code = int(self._batch.code[0])  # a snapshot of an ended episode stays ended
        self._ended = None if code == RUNNING else OUTCOMES[code]
        self._ready = self._ended is None
        return self._batch.obs[0].copy()

    @property
    def episode(self):
        """The current episode's start (trim, parameters, wind speed, perturbation)."""
        return self._batch.episodes[0]

    def __getstate__(self):
        d = dict(self.__dict__)
        d["_renderer"] = None
        return d
