"""``aerostat-gym wind``: generate a turbulence field and print its realised statistics.

Register with ``add_wind_parser(subparsers)``; the parser's ``func`` default is
:func:`wind_command`.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from .. import jsonout
from ..agents.intensity import air_inertia_force
from ..extras import agg_pyplot, require_plotting
from ..params import MAX_WIND_SPEED
from ..physics.wind import PROFILES, W_FIELD_DT, W_TAYLOR_U
from ..wind.field import build_wind, field_heights, field_times, mean_vector
from ..wind.presets import INTENSITY_MODELS, METHODS, PRESETS
from ..wind.sizing import FROM_CONFIG, sized_turbulence
from ..wind.spectra import MODELS
from ..wind.stats import (
    COMPONENTS,
    ensemble_coherence,
    log_band_edges,
    realised_statistics,
    row_of,
    target_coherence,
    target_psd,
    welch_psd,
)
from .common import (
    add_config,
    nonneg_float,
    output_file,
    params_from_args,
    positive_float,
    positive_int,
    seed_int,
)


def add_wind_parser(subparsers) -> argparse.ArgumentParser:
    """Add the ``wind`` sub-command to an ``argparse`` subparsers object."""
    p = subparsers.add_parser(
        "wind", help="generate a seeded turbulence field and print its statistics vs targets",
        description="Generate the turbulence field of one episode and print its realised "
        "statistics (sigma, integral length scale, coherence between heights) next to their "
        "targets. One 600 s record gives rough values; pool seeds with --ensemble.")
    p.add_argument("--preset", default=None, choices=[*PRESETS, FROM_CONFIG],
                   help=f"one of {list(PRESETS)} or '{FROM_CONFIG}' "
                   "(the parameter file's wind.turbulence; default: moderate, or the file's "
                   "preset with --config)")
    p.add_argument("--seed", type=seed_int, default=0, help="seed of numpy.random.default_rng")
    p.add_argument("--duration", type=positive_float, default=600.0, help="episode length [s]")
    p.add_argument("--speed", type=nonneg_float, default=8.0,
                   help="mean speed at the reference height [m/s]")
    p.add_argument("--profile", default=None, choices=sorted(PROFILES),
                   help="mean profile (default: the configuration's wind.profile)")
    p.add_argument("--reference-height", type=positive_float, default=None,
                   help="reference height of the power/log profile [m] (default: the configuration's)")
    p.add_argument("--intensity-model", choices=INTENSITY_MODELS,
                   help="how sigma follows the mean wind (default: the preset's, 'mil')")
    p.add_argument("--model", choices=MODELS, help="override the preset's spectrum")
    p.add_argument("--method", choices=METHODS, help="override the generation method")
    p.add_argument("--height", type=positive_float, help="aerostat nominal height (field advection) [m] "
                   "(default: the configuration's wind.turbulence_reference_height)")
    p.add_argument("--ensemble", type=positive_int, default=1,
                   help="pool this many seeds from --seed on")
    p.add_argument("--plot", metavar="FILE", help="write a PNG (time series, PSD, coherence)")
    add_config(p)
    p.set_defaults(func=wind_command)
    return p


#: [s] the longest record: the standards average turbulence over 10 min to 1 h, the span over
#: which the mean wind is taken as stationary (longer records also cost memory: a field is
#: heights x samples x 3 doubles)
MAX_DURATION_S = 3600.0
#: [bytes] the most memory the pooled fields of --ensemble may take
MAX_ENSEMBLE_BYTES = 2 * 1024**3


def _check_record(args) -> None:
    if args.speed > MAX_WIND_SPEED:
        raise ValueError(f"--speed must be <= {MAX_WIND_SPEED:g} m/s (the model's incompressible "
                         f"aerodynamics end near Mach 0.3), got {args.speed:g}")
    if args.duration > MAX_DURATION_S:
        raise ValueError(f"--duration must be <= {MAX_DURATION_S:g} s (turbulence statistics are "
                         f"stationary over 10 min to 1 h; pool seeds with --ensemble for more), "
                         f"got {args.duration:g}")


def _preset(args) -> str:
    """The intensity class asked for: --preset, else the parameter file's with --config, else
    moderate."""
    return args.preset or (FROM_CONFIG if args.config else "moderate")


def _config(args, params):
    """Preset with the command-line overrides, its field grid sized from the configuration
    (errors are ValueError with a clear message)."""
    cfg = sized_turbulence(params, _preset(args))
    changes = {k: v for k, v in (("model", args.model), ("method", args.method),
                                 ("reference_height", args.height),
                                 ("intensity_model", args.intensity_model)) if v is not None}
    if changes.get("method") == "filter" and "model" not in changes:
        changes["model"] = "dryden"
    return cfg.replace(**changes) if changes else cfg


def _check_plot(args, cfg) -> None:
    """--plot needs a turbulent field and a folder it can write, checked before the field is
    built."""
    if cfg.is_off:
        where = (" (the parameter file's wind.turbulence is 'none')"
                 if _preset(args) == FROM_CONFIG else "")
        raise ValueError(f"--plot {args.plot}: no turbulence to plot{where}; choose a class "
                         f"with --preset ({', '.join(p for p in PRESETS if p != 'none')})")
    require_plotting("--plot")
    output_file(args.plot, "--plot")


def wind_command(args) -> int:
    """Run ``aerostat-gym wind``; returns the exit status (2 on invalid input)."""
    try:
        _check_record(args)
        params = params_from_args(args)
        cfg = _config(args, params)
        if args.plot:
            _check_plot(args, cfg)
        w = params.wind
        mean = {"profile": args.profile or w.profile, "speed": args.speed,
                "reference_height": args.reference_height or w.reference_height,
                "shear_exponent": w.shear_exponent, "roughness_length": w.roughness_length}
        build_wind(mean, cfg, 1.0, np.random.default_rng(0))  # load the compiled kernels
        t0 = time.perf_counter()
        wp, wf = build_wind(mean, cfg, args.duration, np.random.default_rng(args.seed))
        gen_s = time.perf_counter() - t0
        if wf.nbytes * args.ensemble > MAX_ENSEMBLE_BYTES:
            raise ValueError(f"--ensemble {args.ensemble} x {args.duration:g} s would hold "
                             f"{wf.nbytes * args.ensemble / 1024**3:.1f} GiB of fields (at most "
                             f"{MAX_ENSEMBLE_BYTES / 1024**3:g}): fewer seeds or a shorter record")
        fields = [wf] + [build_wind(mean, cfg, args.duration, np.random.default_rng(s))[1]
                         for s in range(args.seed + 1, args.seed + args.ensemble)]
    except (ValueError, TypeError) as e:
        print(f"aerostat-gym wind: error: {e}", file=sys.stderr)
        return 2
    out = {"preset": _preset(args),
           "intensity_model": cfg.intensity_model, "model": cfg.model, "method": cfg.method,
           "seed": args.seed, "duration_s": args.duration, "mean_speed": args.speed,
           "field_shape": list(wf.shape), "generation_s": gen_s}
    cfg = cfg.for_wind(mean_vector(mean))  # the class's sigmas in this mean wind
    if not cfg.is_off:
        out.update(realised_statistics(cfg, wp, fields))
        out["air_inertia"] = _air_inertia(params, cfg, wp, wf, args.duration)
    print(jsonout.dumps(out, indent=2) if args.json else _table(out))
    if args.plot:
        _plot(args.plot, cfg, wp, fields)
    return 0


def _air_inertia(params, cfg, wp, wf, duration: float) -> dict:
    """Air-inertia force on the configured hull held at the field's reference height."""
    return air_inertia_force(params, wp, wf, (0.0, 0.0, cfg.reference_height), duration)


def _table(out: dict) -> str:
    """Human-readable report."""
    head = (f"wind: preset {out['preset']} ({out['model']}, {out['method']}), seed {out['seed']}, "
            f"field {' x '.join(map(str, out['field_shape']))} built in {out['generation_s']:.3f} s")
    if "components" not in out:
        return head + "\nno turbulence: mean wind only"
    lines = [head, f"statistics at {out['height']:.0f} m, U_a = {out['advection_speed']:.2f} m/s, "
             f"{out['seeds']} seed(s) x {out['record_s']:.0f} s",
             f"{'':4}{'sigma [m/s]':>20}{'L_int fit [m]':>22}{'L_int ACF [m]':>16}",
             f"{'':4}{'realised':>10}{'target':>10}{'realised':>12}{'target':>10}{'realised':>16}"]
    for name, c in out["components"].items():
        lines.append(f"{name:4}{c['sigma']:10.3f}{c['sigma_target']:10.3f}"
                     f"{c['integral_length']:12.1f}{c['integral_length_target']:10.1f}"
                     f"{c['integral_length_acf']:16.1f}")
    ai = out["air_inertia"]
    lines.append(f"air inertia on the configured hull held at {out['height']:.0f} m ((1 + k_i) rho V "
                 f"dW_i/dt): RMS axial {ai['rms_axial_n']:.0f} N, lateral {ai['rms_lateral_n']:.0f} N, "
                 f"vertical {ai['rms_vertical_n']:.0f} N, peak |F| {ai['peak_n']:.0f} N "
                 f"(RMS |dW/dt| {ai['rms_air_acceleration_m_s2']:.3f} m/s^2)")
    lines.append("coherence realised/target (IEC), band-averaged around f (n/a: the record is too short for the band):")
    for name, c in out["components"].items():
        for r, d in c["coherence"].items():
            cells = "  ".join(f"{f:g} Hz {_pair(g, w)}" for f, g, w in
                              zip(d["freq_hz"], d["realised"], d["target"], strict=True))
            lines.append(f"  {name} r = {r:>3} m: {cells}")
    return "\n".join(lines)


def _pair(realised: float, target: float) -> str:
    """'realised/target' to two decimals; n/a where the record cannot resolve the band (both
    NaN) or the field has no row that far below (realised NaN)."""
    if math.isnan(target):
        return "n/a"
    return ("n/a" if math.isnan(realised) else f"{realised:.2f}") + f"/{target:.2f}"


def _plot(path: str, cfg, wp, fields) -> None:
    """PNG with the u, v, w series, their PSDs against the analytic ones and the coherence."""
    plt = agg_pyplot("wind --plot")

    wf = np.stack(fields)
    dt, U = wp[W_FIELD_DT], wp[W_TAYLOR_U]
    k0 = row_of(wp, cfg.reference_height) if wf.shape[1] > 1 else 0
    fig, ax = plt.subplots(3, 1, figsize=(8, 10))
    t = field_times(wp, fields[0])
    for c, name in enumerate(COMPONENTS):
        ax[0].plot(t, wf[0, k0, :, c], lw=0.6, label=name)
        f, P = welch_psd(wf[:, k0, :, c], dt, nperseg=min(wf.shape[2], 2048))
        line = ax[1].loglog(f[1:], P[1:], lw=0.8, label=f"{name} realised")[0]
        ax[1].loglog(f[1:], target_psd(cfg, U, c, f[1:]), "--", color=line.get_color(),
                     label=f"{name} target")
    _plot_coherence(ax[2], cfg, wp, wf, k0)
    z = field_heights(wp, fields[0])[k0]
    ax[0].set(xlabel="t [s]", ylabel="fluctuation [m/s]", title=f"{cfg.model} field at {z:.0f} m")
    ax[1].set(xlabel="f [Hz]", ylabel="PSD [(m/s)^2/Hz]")
    for a in ax:
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _plot_coherence(ax, cfg, wp, wf, k0) -> None:
    """u coherence vs frequency for a few separations, with the IEC target."""

    dt, U = wp[W_FIELD_DT], wp[W_TAYLOR_U]
    nseg = min(wf.shape[2], 2048)
    edges = log_band_edges(1.0 / (nseg * dt), 0.5 / dt, per_decade=8, min_bins=3)
    for r in (10.0, 20.0, 50.0):
        k1 = k0 - int(round(r / cfg.dz))
        if wf.shape[1] == 1 or k1 < 0:
            continue
        f, C = ensemble_coherence(wf[:, k0, :, 0], wf[:, k1, :, 0], dt, nseg, edges)
        line = ax.semilogx(f, C, "o-", ms=3, lw=0.8, label=f"u, r = {r:g} m")[0]
        ax.semilogx(f, target_coherence(cfg, U, 0, f, r), "--", color=line.get_color())
    ax.set(xlabel="f [Hz]", ylabel="coherence", ylim=(0, 1.05),
           title="coherence between heights, band-averaged (dashed: IEC target)")
