"""What a Monte Carlo study found: stability probability per mode and wind speed, the spread of
the Table 2 periods and of the smallest damping ratio, and which parameters the instabilities
follow; written as CSV, JSON and one figure."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from .. import jsonout
from ..extras import agg_pyplot
from .montecarlo import MODES, PERIOD_KEYS, Study
from .stats import point_biserial, spearman, wilson_interval

PERCENTILES = (5, 25, 50, 75, 95)
#: Share of a parameter's range at each end used for the conditional instability rates.
TAIL = 0.2
#: A damping ratio at or below this is a real positive eigenvalue (zeta = -1, a divergence).
DIVERGENCE_ZETA = -0.999


def complete_mask(study: Study) -> np.ndarray:
    """Samples whose whole sweep ran (no failed trim, no invalid parameter set)."""
    return np.array([not s.error for s in study.samples])


def stable_everywhere(study: Study) -> np.ndarray:
    """1 where every mode is stable at every speed of the sweep (0 for incomplete samples)."""
    return np.where(complete_mask(study), np.all(study.stack("all_stable") == 1.0, axis=1),
                    False)


def min_zeta(study: Study) -> np.ndarray:
    """Smallest damping ratio of the followed modes over the sweep, per sample (nan if none)."""
    z = study.stack("zeta").reshape(len(study.samples), -1)
    with np.errstate(invalid="ignore"):
        return np.where(np.all(np.isnan(z), axis=1), np.nan,
                        np.nanmin(np.where(np.isnan(z), np.inf, z), axis=1))


def distribution(x: np.ndarray) -> dict:
    """Mean, standard deviation and :data:`PERCENTILES` of the finite entries of ``x``."""
    x = x[np.isfinite(x)]
    if x.size == 0:
        return {"n": 0}
    out = {"n": int(x.size), "mean": float(x.mean()), "std": float(x.std(ddof=1)) if x.size > 1
           else 0.0}
    out.update({f"p{q}": float(v) for q, v in zip(PERCENTILES, np.percentile(x, PERCENTILES),
                                                   strict=True)})
    return out


def stability_table(study: Study) -> list[dict]:
    """One row per (wind speed, mode) plus ``all modes``: P(stable) with its Wilson 95 % CI
    over the samples where the mode was found at that speed."""
    stable, every = study.stack("stable"), study.stack("all_stable")
    rows = []
    for k, u in enumerate(study.speeds):
        cols = [(f"{s} {lab}", stable[:, k, j]) for j, (s, lab) in enumerate(MODES)]
        for name, col in [*cols, ("all modes", every[:, k])]:
            ok = col[~np.isnan(col)]
            lo, hi = wilson_interval(int(ok.sum()), ok.size)
            rows.append({"wind_speed_m_s": float(u), "mode": name, "n": int(ok.size),
                         "p_stable": float(ok.mean()) if ok.size else math.nan,
                         "ci95_low": lo, "ci95_high": hi})
    return rows


def _tail_rates(x: np.ndarray, unstable: np.ndarray, low: float, high: float) -> tuple:
    """Instability rate among samples in the lowest and highest :data:`TAIL` of the range."""
    span = high - low
    lo_sel, hi_sel = x <= low + TAIL * span, x >= high - TAIL * span

    def rate(sel: np.ndarray) -> float:
        return float(unstable[sel].mean()) if sel.any() else math.nan

    return rate(lo_sel), rate(hi_sel)


def correlations(study: Study) -> list[dict]:
    """Per parameter, over the complete samples: point-biserial r with "unstable somewhere",
    Spearman rho with the largest Re(lambda) over the sweep, and the instability rate in the
    lowest and highest fifth of its range; sorted by |r| (then |rho|)."""
    ok = complete_mask(study)
    if ok.sum() < 2:
        return []
    values = study.stack("values")[ok]
    unstable = (~stable_everywhere(study)[ok]).astype(float)
    margin = np.nanmax(study.stack("max_real")[ok], axis=1)
    rows = []
    for i, key in enumerate(study.keys):
        lo, hi = study.ranges[i]
        low_rate, high_rate = _tail_rates(values[:, i], unstable, lo, hi)
        rows.append(dict(zip(CORRELATION_FIELDS, (
            key, lo, hi, point_biserial(values[:, i], unstable), spearman(values[:, i], margin),
            low_rate, high_rate), strict=True)))

    def order(r):
        a, b = abs(r["r_unstable"]), abs(r["rho_max_real"])
        return (-(a if math.isfinite(a) else -1), -(b if math.isfinite(b) else -1))

    return sorted(rows, key=order)


def mode_instability_drivers(study: Study) -> list[dict]:
    """For each followed mode that is unstable somewhere in some sample: how many samples
    (``samples_unstable``, over every sample and the speeds its sweep reached, as the
    stability table counts), the speeds, and the parameter with the largest |point-biserial r|
    with that instability over the ``complete`` samples (``top_parameter`` and ``r``, None and
    nan where r is undefined, with the reason in ``no_r``)."""
    ok = complete_mask(study)
    stable, values = study.stack("stable"), study.stack("values")[ok]
    out = []
    for j, (subset, label) in enumerate(MODES):
        hit = np.any(stable[:, :, j] == 0.0, axis=1)
        if not hit.any():
            continue
        r = [point_biserial(values[:, i], hit[ok]) for i in range(len(study.keys))]
        best = int(np.nanargmax(np.abs(r))) if np.any(np.isfinite(r)) else None
        speeds = study.speeds[np.any(stable[:, :, j] == 0.0, axis=0)]
        out.append({"mode": f"{subset} {label}", "samples_unstable": int(hit.sum()),
                    "speeds_m_s": [float(u) for u in speeds], "complete": int(ok.sum()),
                    "complete_unstable": int(hit[ok].sum()),
                    "top_parameter": study.keys[best] if best is not None else None,
                    "r": r[best] if best is not None else math.nan,
                    "no_r": None if best is not None else _why_no_r(int(ok.sum()),
                                                                     int(hit[ok].sum()))})
    return out


def _why_no_r(complete: int, unstable: int) -> str:
    """Why no parameter's point-biserial r with an instability is defined: it needs two
    complete sweeps, the instability in some and not in others, and a parameter that varies."""
    if complete < 2:
        return f"r needs 2 complete sweeps, {complete} ran"
    if unstable in (0, complete):
        return (f"{unstable} of the {complete} complete sweeps are unstable in it (r needs both "
                "outcomes)")
    return "no drawn parameter varies over the complete sweeps"


def summarize(study: Study, nominal=None) -> dict:
    """Everything the report prints, as plain numbers (JSON-ready).

    Parameters
    ----------
    study : the Monte Carlo run.
    nominal : optional :class:`~aerostat_gym.scale.montecarlo.SampleResult` of the base set.
    """
    n, ok = len(study.samples), complete_mask(study)
    every = stable_everywhere(study)
    lo, hi = wilson_interval(int(every.sum()), n)
    periods = study.stack("periods")
    out = {
        "samples": n, "seed": study.seed, "backend": study.backend,
        "seconds": study.seconds, "sets_per_s": n / study.seconds if study.seconds else None,
        "meta": study.meta, "speeds_m_s": [float(u) for u in study.speeds],
        "parameters": [{"key": k, "low": r[0], "high": r[1], "nominal": v}
                       for k, r, v in zip(study.keys, study.ranges, study.nominal, strict=True)],
        "complete": int(ok.sum()), "errors": [s.error for s in study.samples if s.error][:10],
        "n_errors": int((~ok).sum()),
        "rejected_draws": int(study.meta.get("rejected", 0)),
        "rejections": list(study.meta.get("rejections", [])),
        "stable_everywhere": {"count": int(every.sum()), "fraction": float(every.mean()),
                              "ci95": [lo, hi],
                              "fraction_of_complete": float(every[ok].mean()) if ok.any()
                              else math.nan},
        "periods_s": {key: distribution(periods[:, i]) for i, key in enumerate(PERIOD_KEYS)},
        "min_zeta": {**distribution(min_zeta(study)),
                     "divergences": int(np.sum(min_zeta(study) <= DIVERGENCE_ZETA))},
        "stability": stability_table(study),
        "correlations": correlations(study),
        "mode_instabilities": mode_instability_drivers(study),
    }
    if nominal is not None:
        out["nominal"] = {"periods_s": dict(zip(PERIOD_KEYS, nominal.periods.tolist(),
                                                strict=True)),
                          "stable_everywhere": bool(np.all(nominal.all_stable == 1.0)),
                          "min_zeta": float(np.nanmin(nominal.zeta))}
    return out


def sample_rows(study: Study) -> list[dict]:
    """One CSV row per sample: drawn values, outcome, Table 2 periods, margins."""
    every, zmin = stable_everywhere(study), min_zeta(study)
    rows = []
    for i, s in enumerate(study.samples):
        row = {"sample": i, **dict(zip(study.keys, s.values.tolist(), strict=True)),
               "stable_everywhere": int(every[i]), "min_zeta": zmin[i],
               "max_real_1_s": float(np.nanmax(s.max_real)) if np.any(np.isfinite(s.max_real))
               else math.nan}
        row.update({f"{k}_s": v for k, v in zip(PERIOD_KEYS, s.periods.tolist(), strict=True)})
        row["error"] = s.error
        rows.append(row)
    return rows


CORRELATION_FIELDS = ("parameter", "low", "high", "r_unstable", "rho_max_real",
                      "unstable_rate_low_fifth", "unstable_rate_high_fifth")


def _write_csv(path: Path, rows: list[dict], fields=None) -> None:
    """Rows as CSV; with no rows, the header of ``fields`` only."""
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else list(fields or ()))
        w.writeheader()
        w.writerows(rows)


def write_outputs(study: Study, summary: dict, out: Path, plot: bool = True) -> list[Path]:
    """samples.csv, stability.csv, correlations.csv, summary.json (and montecarlo.png).

    Parameters
    ----------
    study : the Monte Carlo run.
    summary : :func:`summarize` of it.
    out : output directory (created).
    plot : also draw the figure (needs matplotlib).
    """
    out.mkdir(parents=True, exist_ok=True)
    files = [out / "samples.csv", out / "stability.csv", out / "correlations.csv",
             out / "summary.json"]
    _write_csv(files[0], sample_rows(study))
    _write_csv(files[1], summary["stability"])
    _write_csv(files[2], summary["correlations"], CORRELATION_FIELDS)
    files[3].write_text(jsonout.dumps(summary, indent=1, default=float))
    if plot:
        files.append(plot_study(study, summary, out / "montecarlo.png"))
    return files


def plot_study(study: Study, summary: dict, path: Path) -> Path:
    """Four panels: P(stable) against wind speed per mode, the Table 2 period histograms
    (relative to their medians), the smallest damping ratio, and the correlations."""
    plt = agg_pyplot("the Monte Carlo figure (--no-plot skips it)")

    fig, ax = plt.subplots(2, 2, figsize=(12, 8.5))
    _plot_probability(ax[0, 0], summary)
    _plot_periods(ax[0, 1], study)
    _plot_min_zeta(ax[1, 0], min_zeta(study))
    _plot_correlations(ax[1, 1], summary)
    frac = summary["stable_everywhere"]
    fig.suptitle(f"Monte Carlo on {summary['meta'].get('configuration', 'baseline')}, "
                 f"{summary['samples']} parameter sets (seed {summary['seed']}): "
                 f"{100 * frac['fraction']:.1f} % stable at every wind speed")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _plot_probability(a, summary: dict) -> None:
    rows = summary["stability"]
    for name in dict.fromkeys(r["mode"] for r in rows):
        pts = [(r["wind_speed_m_s"], r["p_stable"]) for r in rows if r["mode"] == name]
        u, p = np.array(pts).T
        every = name == "all modes"
        a.plot(u, p, "k--" if every else "-", marker="" if every else ".", label=name,
               lw=1.6 if every else 1.2, zorder=3 if every else 2)
    a.set(xlabel="wind speed [m/s]", ylabel="P(stable)", title="probability that a mode is stable",
          ylim=(-0.02, 1.02))
    a.legend(fontsize=7, ncol=2)


def _plot_periods(a, study: Study) -> None:
    periods = study.stack("periods")
    for i, key in enumerate(PERIOD_KEYS):
        x = periods[:, i][np.isfinite(periods[:, i])]
        if x.size:
            a.hist(x / np.median(x), bins=40, histtype="step", label=f"{key} (median "
                   f"{np.median(x):.3g} s)")
    a.set(xlabel="period / median", ylabel="parameter sets", title="Table 2 periods at 1 m/s")
    a.legend(fontsize=7)


def _plot_min_zeta(a, zmin: np.ndarray) -> None:
    z = zmin[np.isfinite(zmin)]
    divergent = int(np.sum(z <= DIVERGENCE_ZETA))
    a.hist(z[z > DIVERGENCE_ZETA], bins=50, color="tab:blue")
    a.axvline(0.0, color="k", lw=0.8)
    a.set(xlabel="smallest damping ratio over the sweep", ylabel="parameter sets",
          title=f"smallest damping ratio ({divergent} sets with a divergence, zeta = -1, "
          "not shown)")


def _plot_correlations(a, summary: dict) -> None:
    rows = summary["correlations"]
    names = [r["parameter"] for r in rows]
    y = np.arange(len(rows))
    a.barh(y - 0.2, [r["r_unstable"] for r in rows], 0.4, label="r with 'unstable somewhere'")
    a.barh(y + 0.2, [r["rho_max_real"] for r in rows], 0.4, label="Spearman rho with max Re(lambda)")
    a.set_yticks(y, names, fontsize=7)
    a.invert_yaxis()
    a.axvline(0, color="k", lw=0.8)
    a.set(xlabel="correlation", title="which parameters the instabilities follow")
    a.legend(fontsize=7)
