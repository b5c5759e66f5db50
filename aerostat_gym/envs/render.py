"""Matplotlib renderer of the tethered aerostat for the Gymnasium environment.

The image has three panels, all orthographic projections with equal axis scales:

* **side view** (inertial X-Z, left): ground, winch, the whole tether, the hull and fins, a wind
  arrow with its speed, the trim position (optional);
* **close-up** (X-Z relative to the CM, upper right): the hull, fins, the top of the tether and
  the horizon through the CM, with the Euler angles, so pitch and roll motions stay visible
  even though the hull is only a few pixels long in the side view;
* **top view** (inertial X-Y, lower right): tether, hull, fins and the wind arrow.

A header line reads out time, winch tension, tether length and reel speed.

``rgb_array`` draws on a private Agg canvas (no pyplot, no display) and blits: the axes, ticks
and ground are drawn once into a background, each frame restores it and draws only the moving
artists, so a frame costs a few milliseconds. The axis limits are fixed by the first frame (from
the tether length) and only grow if the aerostat leaves them. ``human`` opens a pyplot window;
without a display it warns once and renders off-screen.

Frames (see the README): inertial X, Y, Z with Z up and the winch at the origin; body x to the
nose, y to port, z up; Z-Y-X Euler angles, :func:`aerostat_gym.physics.core.rotation_matrix`
gives the body-to-inertial matrix. The hull and fins are drawn from the parameter set.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..extras import MissingExtraError, require_plotting
from ..params import Params
from ..physics.core import rotation_matrix

RENDER_MODES = ("rgb_array", "human")

# Colours; the hull fill is distinctive so tests (and eyes) can find it.
HULL_COLOR = "#e8601c"
HULL_EDGE = "#9c3d0e"
FIN_COLOR = "#4b5d8f"
TETHER_COLOR = "#303030"
SKY_COLOR = "#eef4fa"
GROUND_COLOR = "#c9b48a"
WIND_COLOR = "#1f6fb4"
TRIM_COLOR = "#2a9d3a"

# Projections: inertial columns shown as (horizontal, vertical), and the depth axis with its
# sign (a larger depth is farther from the viewer, drawn first). The side view looks along +Y.
SIDE = ((0, 2), 1, 1.0)
TOP = ((0, 1), 2, -1.0)

_DPI = 100
_N_DIRECTIONS = 96  # silhouette vertices of the hull outline
_N_RINGS = 41  # cross-sections of the hull body of revolution
_FIN_TAPER = 0.6  # tip chord / root chord of the drawn fin planform
_NOSE_STATION = 0.4  # fraction of the hull length, nose to maximum diameter


@dataclass
class Frame:
    """What one rendered image shows (SI units, inertial frame, Z up).

    Attributes
    ----------
    time : float
        Simulation time [s].
    nodes : ndarray, shape (n + 1, 3)
        Tether node positions, confluence point first, anchor last [m].
    cm_pos : ndarray, shape (3,)
        Aerostat centre of mass [m].
    euler : ndarray, shape (3,)
        Roll, pitch, yaw (phi, theta, psi), Z-Y-X sequence [rad].
    wind : ndarray, shape (3,)
        Mean or measured wind at the aerostat [m/s].
    tension : float
        Winch tension [N].
    length : float
        Tether length paid out [m].
    reel_speed : float
        Reel-out speed [m/s] (positive pays line out).
    trim_cm : ndarray, shape (3,), optional
        Trim position of the CM to mark [m].
    """

    time: float
    nodes: np.ndarray
    cm_pos: np.ndarray
    euler: np.ndarray
    wind: np.ndarray
    tension: float
    length: float
    reel_speed: float
    trim_cm: np.ndarray | None = None


# --- geometry (body frame, no matplotlib) ---------------------------------------------------------


@dataclass(frozen=True)
class AerostatShape:
    """Hull and fin geometry in body coordinates relative to the CM.

    Attributes
    ----------
    ring_centres : ndarray, shape (m, 3)
        Centres of the hull cross-sections, nose first.
    ring_radii : ndarray, shape (m,)
        Their radii (zero at nose and tail).
    centre : ndarray, shape (3,)
        Mid-point of the hull axis.
    fins : ndarray, shape (k, 4, 3)
        Fin planforms: root leading edge, root trailing edge, tip trailing edge, tip leading edge.
    """

    ring_centres: np.ndarray
    ring_radii: np.ndarray
    centre: np.ndarray
    fins: np.ndarray
    length: float


def hull_radius(xi: np.ndarray, radius: float) -> np.ndarray:
    """Streamlined body of revolution: radius at the fraction ``xi`` of the length from the nose.

    An elliptic nose up to the maximum diameter at 40 % of the length and a fuller, rounded
    tail ``(1 - u^2)^0.75``; the profile is concave, so the hull is convex (its silhouette is
    the support of its cross-sections).
    """
    xi = np.clip(np.asarray(xi, float), 0.0, 1.0)
    fore = (_NOSE_STATION - xi) / _NOSE_STATION
    aft = (xi - _NOSE_STATION) / (1.0 - _NOSE_STATION)
    u = np.where(xi < _NOSE_STATION, fore, aft)
    base = np.clip(1.0 - u * u, 0.0, None)
    return radius * np.where(xi < _NOSE_STATION, np.sqrt(base), base**0.75)


def aerostat_shape(params: Params) -> AerostatShape:
    """Hull and fins of ``params`` in body coordinates (x to the nose, y to port, z up).

    The hull axis runs from ``aerostat.nose_position`` aft over ``aerostat.length`` with the
    maximum diameter ``aerostat.diameter``. Each fin is a tapered planform in the plane of the
    hull axis and its span direction (0, sin, cos) of ``roll_angle_deg``, centred on its
    quarter-chord mid-span point ``cp_position``; the span follows from the aspect ratio
    (AR = 2 b^2 / A, hull as reflection plane) and the root reaches into the hull.
    """
    a = params.aerostat
    nose = np.asarray(a.nose_position, float)
    radius = 0.5 * a.diameter
    xi = 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, _N_RINGS)))  # dense at nose and tail
    centres = nose[None, :] - np.outer(xi * a.length, [1.0, 0.0, 0.0])
    radii = hull_radius(xi, radius)
    fins = [_fin_planform(params, pan, nose, radius) for pan in params.fins.panels]
    fins = np.array(fins, float).reshape(-1, 4, 3)
    centre = nose - np.array([0.5 * a.length, 0.0, 0.0])
    return AerostatShape(centres, radii, centre, fins, float(a.length))


def _fin_planform(params: Params, panel, nose: np.ndarray, radius: float) -> np.ndarray:
    """Four corners (4, 3) of one fin: root LE, root TE, tip TE, tip LE (body frame)."""
    f = params.fins
    span = math.sqrt(max(f.aspect_ratio * f.planform_area, 0.0) / 2.0)
    if span <= 0.0:
        return np.zeros((0, 3))
    g = math.radians(panel.roll_angle_deg)
    s_hat = np.array([0.0, math.sin(g), math.cos(g)])
    x_hat = np.array([1.0, 0.0, 0.0])
    cp = np.asarray(panel.cp_position, float)
    # distance of the mid-span point from the hull axis, and the hull radius at that station
    d_mid = float(np.dot(cp - nose, s_hat))
    r_station = float(hull_radius((nose[0] - cp[0]) / params.aerostat.length, radius))
    d_root = min(d_mid - 0.5 * span, 0.95 * r_station)
    d_tip = d_mid + 0.5 * span
    root, tip = cp + (d_root - d_mid) * s_hat, cp + (d_tip - d_mid) * s_hat
    # quarter-chord line unswept; chords linear in span with the mean chord A / b
    c_root = 2.0 * (f.planform_area / span) / (1.0 + _FIN_TAPER)
    c_tip = _FIN_TAPER * c_root
    return np.array([root + 0.25 * c_root * x_hat, root - 0.75 * c_root * x_hat,
                     tip - 0.75 * c_tip * x_hat, tip + 0.25 * c_tip * x_hat])


def silhouette(shape: AerostatShape, R: np.ndarray, cm: np.ndarray, cols: tuple[int, int],
               n_dir: int = _N_DIRECTIONS) -> np.ndarray:
    """Projected outline (n_dir, 2) of the hull, a convex body of revolution.

    For each of ``n_dir`` directions u in the view plane, the support point is the extreme point
    of the cross-section circles along u (exact for circles, whatever the orientation).
    """
    centres = cm[None, :] + shape.ring_centres @ R.T
    axis = R[:, 0]
    ang = np.linspace(0.0, 2.0 * math.pi, n_dir, endpoint=False)
    m = np.zeros((n_dir, 3))
    m[:, cols[0]], m[:, cols[1]] = np.cos(ang), np.sin(ang)
    am = m @ axis  # component of each direction along the hull axis
    perp = m - np.outer(am, axis)  # direction within the cross-section plane
    norm = np.sqrt(np.clip(1.0 - am * am, 0.0, None))
    support = centres @ m.T + np.outer(shape.ring_radii, norm)  # (rings, directions)
    j = np.argmax(support, axis=0)
    unit = perp / np.where(norm > 1e-9, norm, 1.0)[:, None]
    pts = centres[j] + shape.ring_radii[j, None] * unit
    return pts[:, cols]


# --- limits ---------------------------------------------------------------------------------------


def _fit_equal(x_lo: float, x_hi: float, y_lo: float, y_hi: float,
               box_px: tuple[float, float]) -> tuple[tuple[float, float], tuple[float, float]]:
    """Grow the smaller range about its centre so that one metre has the same pixels in x and y."""
    w, h = box_px
    scale = min(w / (x_hi - x_lo), h / (y_hi - y_lo))  # pixels per metre
    xc, yc = 0.5 * (x_lo + x_hi), 0.5 * (y_lo + y_hi)
    hx, hy = 0.5 * w / scale, 0.5 * h / scale
    return (xc - hx, xc + hx), (yc - hy, yc + hy)


def _inside(pts: np.ndarray, xlim, ylim, margin: float) -> bool:
    return bool(np.all(pts[:, 0] >= xlim[0] + margin) and np.all(pts[:, 0] <= xlim[1] - margin)
                and np.all(pts[:, 1] >= ylim[0] + margin) and np.all(pts[:, 1] <= ylim[1] - margin))


# --- renderer -------------------------------------------------------------------------------------


class Renderer:
    """Draw :class:`Frame` objects as RGB images or in a window.

    Parameters
    ----------
    params : Params
        Parameter set (hull, fins and anchor geometry).
    render_mode : {"rgb_array", "human"}
        ``rgb_array``: :meth:`render` returns a C-contiguous uint8 array (height, width, 3).
        ``human``: :meth:`render` updates a pyplot window and returns None.
    width, height : int
        Image size in pixels (rgb_array) or window size at 100 dpi (human).
    fps : int
        Frames per second of the human window (pause between frames).

    Raises
    ------
    ValueError
        ``render_mode`` is not one of ``RENDER_MODES`` (None included), or a size is invalid.
    """

    def __init__(self, params: Params, render_mode: str | None, width: int = 800,
                 height: int = 480, fps: int = 10):
        if render_mode not in RENDER_MODES:
            raise ValueError(f"render_mode {render_mode!r} is not supported; "
                             f"choose one of {RENDER_MODES}")
        if int(width) < 64 or int(height) < 64:
            raise ValueError(f"image size {width} x {height} is too small (64 x 64 at least)")
        if fps <= 0:
            raise ValueError(f"fps must be positive, got {fps}")
        _require_matplotlib()
        self.params = params
        self.render_mode = render_mode
        self.width, self.height, self.fps = int(width), int(height), int(fps)
        self.shape = aerostat_shape(params)
        self.anchor = np.asarray(params.tether.anchor_position, float)
        self._fig = None
        self._headless = False  # human mode without a display

    # -- public API --------------------------------------------------------------------------------

    @property
    def figure(self):
        """The matplotlib Figure (None before the first :meth:`render` and after :meth:`close`)."""
        return self._fig

    def render(self, frame: Frame) -> np.ndarray | None:
        """Draw ``frame``; return the RGB image (rgb_array) or None (human)."""
        if self._fig is None:
            self._build()
        geo = self._geometry(frame)
        if not self._limits_ok(geo):
            self._set_limits(frame, geo)
            self._draw_background()
        self._update(frame, geo)
        if self.render_mode == "human" and not self._headless:
            return self._show()
        self._blit(geo)
        if self.render_mode == "human":
            return None
        buf = np.asarray(self._canvas.buffer_rgba())
        return np.ascontiguousarray(_fit_size(buf[:, :, :3], self.height, self.width))

    def project_side(self, point) -> tuple[int, int]:
        """Pixel (row, col) of an inertial point in the side view of the last rendered image.

        Rows count down from the top edge, as in the arrays :meth:`render` returns; floor the
        continuous position (valid for rgb_array; a human window may use another dpi).
        """
        return self._project(self._ax_side, np.asarray(point, float)[[0, 2]])

    def project_top(self, point) -> tuple[int, int]:
        """Pixel (row, col) of an inertial point in the top view of the last rendered image."""
        return self._project(self._ax_top, np.asarray(point, float)[[0, 1]])

    def close(self) -> None:
        """Release the figure (and close the window); a later :meth:`render` builds a new one."""
        if self._fig is not None and self.render_mode == "human" and not self._headless:
            import matplotlib.pyplot as plt

            plt.close(self._fig)
        self._fig = None

    # -- figure construction -----------------------------------------------------------------------

    def _build(self) -> None:
        """Create the figure, the three axes and every artist (data filled in per frame)."""
        from matplotlib.figure import Figure

        size = ((self.width + 0.01) / _DPI, (self.height + 0.01) / _DPI)  # int() must not round down
        fig = None
        if self.render_mode == "human":
            fig = self._human_figure(size)
        if fig is None:
            from matplotlib.backends.backend_agg import FigureCanvasAgg

            fig = Figure(figsize=size, dpi=_DPI)
            FigureCanvasAgg(fig)
        self._fig, self._canvas = fig, fig.canvas
        self._blitting = not (self.render_mode == "human" and not self._headless)
        self._fs = max(5.0, 7.5 * min(self.width / 800.0, self.height / 480.0))
        fig.patch.set_facecolor("white")
        # panel rectangles in figure fractions (left, bottom, width, height)
        self._ax_side = self._axes((0.075, 0.085, 0.355, 0.83), "side view (X-Z)", "X [m]", "Z [m]")
        self._ax_close = self._axes((0.52, 0.53, 0.465, 0.385), "close-up (relative to CM)",
                                    None, "[m]")
        self._ax_top = self._axes((0.52, 0.085, 0.465, 0.36), "top view (X-Y)", "X [m]", "Y [m]")
        self._static_artists()
        self._moving = {"side": self._body_artists(self._ax_side),
                        "close": self._body_artists(self._ax_close),
                        "top": self._body_artists(self._ax_top)}
        self._extra_artists()
        self._limits = None

    def _human_figure(self, size):
        """A pyplot figure in interactive mode, or None (with a warning) without a display."""
        import matplotlib

        backend = str(matplotlib.get_backend()).lower()
        if backend in ("agg", "pdf", "ps", "svg", "pgf", "cairo", "template"):
            warnings.warn(f"render_mode='human' needs an interactive matplotlib backend (the "
                          f"backend is {backend!r}, no display?); rendering off-screen instead",
                          RuntimeWarning, stacklevel=4)
            self._headless = True
            return None
        import matplotlib.pyplot as plt

        plt.ion()
        fig = plt.figure(figsize=size, dpi=_DPI)
        if fig.canvas.manager is not None:
            fig.canvas.manager.set_window_title("aerostat-gym")
        plt.show(block=False)
        return fig

    def _axes(self, rect, title, xlabel, ylabel):
        ax = self._fig.add_axes(rect)
        ax.set_facecolor(SKY_COLOR)
        ax.tick_params(labelsize=self._fs, length=2, pad=1.5)
        ax.text(0.015, 0.975, title, transform=ax.transAxes, va="top", ha="left",
                fontsize=self._fs, color="0.25")
        if xlabel:
            ax.set_xlabel(xlabel, fontsize=self._fs, labelpad=1)
        ax.set_ylabel(ylabel, fontsize=self._fs, labelpad=1)
        ax.set_autoscale_on(False)
        return ax

    def _static_artists(self) -> None:
        """Ground and winch in the side view, horizon and CM cross in the close-up, winch on top."""
        from matplotlib.patches import Rectangle

        ax = self._ax_side
        z0 = self.anchor[2]
        # the ground: a band below the winch height, wide enough for any limits
        ax.add_patch(Rectangle((-1e5, z0 - 1e5), 2e5, 1e5, facecolor=GROUND_COLOR,
                               edgecolor="none", zorder=0.5))
        ax.axhline(z0, color="#7a6a48", lw=1.0, zorder=0.6)
        for a, (i, j) in ((ax, (0, 2)), (self._ax_top, (0, 1))):
            a.plot([self.anchor[i]], [self.anchor[j]], marker="s", ms=4, color="k", zorder=3)
        self._ax_close.axhline(0.0, color="0.6", lw=0.8, ls="--", zorder=0.6)
        self._ax_close.plot([0.0], [0.0], marker="+", ms=6, color="k", zorder=4)

    def _body_artists(self, ax) -> dict:
        """Tether line, hull polygon, fin polygons and trim marker of one panel."""
        from matplotlib.patches import Polygon

        anim = self._blitting
        tether, = ax.plot([], [], color=TETHER_COLOR, lw=1.0, marker="o", ms=1.8,
                          zorder=1.5, animated=anim)
        hull = Polygon(np.zeros((3, 2)), closed=True, facecolor=HULL_COLOR, edgecolor=HULL_EDGE,
                       lw=0.6, zorder=2.5, animated=anim)
        ax.add_patch(hull)
        fins = []
        for _ in range(len(self.shape.fins)):
            fin = Polygon(np.zeros((3, 2)), closed=True, facecolor=FIN_COLOR, edgecolor=FIN_COLOR,
                          lw=0.8, zorder=2.0, animated=anim)
            ax.add_patch(fin)
            fins.append(fin)
        trim, = ax.plot([], [], ls="none", marker="x", ms=5, mew=1.2, color=TRIM_COLOR,
                        zorder=4, animated=anim)
        return {"ax": ax, "tether": tether, "hull": hull, "fins": fins, "trim": trim}

    def _extra_artists(self) -> None:
        """Wind arrows and labels, the close-up angle readout and the header line."""
        anim, fs = self._blitting, self._fs
        self._wind = {}
        for key, ax, pos in (("side", self._ax_side, (0.72, 0.9)), ("top", self._ax_top,
                                                                     (0.85, 0.8))):
            arrow = ax.annotate("", xy=pos, xytext=pos, xycoords="axes fraction",
                                textcoords="axes fraction", animated=anim, zorder=5,
                                arrowprops={"arrowstyle": "-|>", "color": WIND_COLOR,
                                            "lw": 1.6, "mutation_scale": 10})
            below = pos[1] - 40.0 / self._box_px(ax)[1]  # under the longest (70 px) arrow
            label = ax.text(pos[0], below, "", transform=ax.transAxes, ha="center",
                            va="top", fontsize=fs, color=WIND_COLOR, animated=anim, zorder=5)
            self._wind[key] = (arrow, label, pos)
        self._angles = self._ax_close.text(0.985, 0.975, "", transform=self._ax_close.transAxes,
                                           ha="right", va="top", fontsize=fs, family="monospace",
                                           animated=anim, zorder=5)
        self._header = self._fig.text(0.5, 0.985, "", ha="center", va="top", fontsize=fs + 1,
                                      family="monospace", animated=anim)

    # -- limits ------------------------------------------------------------------------------------

    def _box_px(self, ax) -> tuple[float, float]:
        pos = ax.get_position()
        return pos.width * self.width, pos.height * self.height

    def _set_limits(self, frame: Frame, geo: dict) -> None:
        """Side and top limits from the tether length (grown to contain the current frame)."""
        rel = np.asarray(frame.cm_pos, float) - self.anchor
        reach = max(float(frame.length), float(np.linalg.norm(rel)), 10.0) * 1.08
        reach += self.shape.length
        if self._limits is not None:  # the aerostat left the view: grow, never shrink
            reach = max(reach, 1.25 * self._limits["reach"])
        wind_x = float(np.asarray(frame.wind, float)[0])
        if abs(rel[0]) > 0.02 * reach:
            sign = math.copysign(1.0, rel[0])
        else:
            sign = math.copysign(1.0, wind_x) if abs(wind_x) > 0.1 else 1.0
        # downwind side 0.6 reach (blow-by up to ~37 deg), upwind 0.2 reach
        xs = sorted((self.anchor[0] - sign * 0.2 * reach, self.anchor[0] + sign * 0.6 * reach))
        side_x, side_z = self._grow(xs, (self.anchor[2] - 0.06 * reach, self.anchor[2] + reach),
                                    geo["side_pts"], self._ax_side)
        half_y = 0.1 * reach
        top_x, top_y = self._grow(side_x, (self.anchor[1] - half_y, self.anchor[1] + half_y),
                                  geo["top_pts"], self._ax_top)
        # close-up: the hull with the confluence point below, in metres from the CM
        b = np.vstack([self.shape.ring_centres, self.shape.fins.reshape(-1, 3)])
        half = 0.5 * self.shape.length + 0.2 * self.shape.length
        z_lo = min(float(self.params.aerostat.leash_z), float(b[:, 2].min())) - 1.5
        z_hi = float(b[:, 2].max()) + 0.5 * self.params.aerostat.diameter
        close_x, close_z = _fit_equal(-half, half, z_lo, z_hi, self._box_px(self._ax_close))
        for ax, xl, yl in ((self._ax_side, side_x, side_z), (self._ax_top, top_x, top_y),
                           (self._ax_close, close_x, close_z)):
            ax.set_xlim(*xl)
            ax.set_ylim(*yl)
        self._limits = {"reach": reach, "side": (side_x, side_z), "top": (top_x, top_y)}

    def _grow(self, xr, yr, pts: np.ndarray, ax):
        """Equal-scale limits covering the ranges xr, yr and the points (with a margin)."""
        pad = 0.5 * self.shape.length
        x_lo, x_hi = min(xr[0], pts[:, 0].min() - pad), max(xr[1], pts[:, 0].max() + pad)
        y_lo, y_hi = min(yr[0], pts[:, 1].min() - pad), max(yr[1], pts[:, 1].max() + pad)
        return _fit_equal(x_lo, x_hi, y_lo, y_hi, self._box_px(ax))

    def _limits_ok(self, geo: dict) -> bool:
        if self._limits is None:
            return False
        return (_inside(geo["side_pts"], *self._limits["side"], 0.0)
                and _inside(geo["top_pts"], *self._limits["top"], 0.0))

    def _draw_background(self) -> None:
        """Draw everything that does not move and keep it for blitting."""
        if not self._blitting:
            return
        self._canvas.draw()
        self._background = self._canvas.copy_from_bbox(self._fig.bbox)

    # -- per-frame update --------------------------------------------------------------------------

    def _geometry(self, frame: Frame) -> dict:
        """Hull outlines, fin corners and the points that must stay in view, inertial frame."""
        cm = np.asarray(frame.cm_pos, float).reshape(3)
        nodes = np.asarray(frame.nodes, float).reshape(-1, 3)
        euler = np.asarray(frame.euler, float).reshape(3)
        R = np.asarray(rotation_matrix(euler[0], euler[1], euler[2]))
        fins = cm + self.shape.fins @ R.T  # (k, 4, 3)
        side = silhouette(self.shape, R, cm, SIDE[0])
        top = silhouette(self.shape, R, cm, TOP[0])
        must = np.vstack([nodes, cm[None, :]])
        return {"cm": cm, "nodes": nodes, "R": R, "fins": fins, "side": side, "top": top,
                "hull_centre": cm + R @ self.shape.centre,
                "side_pts": np.vstack([must[:, [0, 2]], side]),
                "top_pts": np.vstack([must[:, [0, 1]], top])}

    def _update(self, frame: Frame, geo: dict) -> None:
        """Set the data of every moving artist."""
        cm, trim = geo["cm"], frame.trim_cm
        for key, view, offset, outline in (("side", SIDE, 0.0, geo["side"]),
                                           ("close", SIDE, cm, geo["side"] - cm[[0, 2]]),
                                           ("top", TOP, 0.0, geo["top"])):
            (i, j), depth, sign = view
            art = self._moving[key]
            nodes = geo["nodes"] - offset
            art["tether"].set_data(nodes[:, i], nodes[:, j])
            art["hull"].set_xy(outline)
            for fin, corners in zip(art["fins"], geo["fins"], strict=True):
                c = corners - offset
                fin.set_xy(c[:, [i, j]])
                # fins farther than the hull axis are drawn behind the hull
                far = sign * (corners[:, depth].mean() - geo["hull_centre"][depth]) > 0.0
                fin.set_zorder(2.0 if far else 3.0)
            if trim is None:
                art["trim"].set_data([], [])
            else:
                t = np.asarray(trim, float) - offset
                art["trim"].set_data([t[i]], [t[j]])
        self._update_text(frame)

    def _update_text(self, frame: Frame) -> None:
        wind = np.asarray(frame.wind, float).reshape(3)
        speed = float(np.linalg.norm(wind))
        for key, (i, j) in (("side", SIDE[0]), ("top", TOP[0])):
            arrow, label, pos = self._wind[key]
            ax = self._ax_side if key == "side" else self._ax_top
            w_px, h_px = self._box_px(ax)
            # 4 px per m/s, at most 70 px; the arrow is centred on pos
            k = min(4.0, 70.0 / speed) if speed > 0 else 0.0
            dx, dy = 0.5 * k * wind[i] / w_px, 0.5 * k * wind[j] / h_px
            arrow.xy = (pos[0] + dx, pos[1] + dy)
            arrow.set_position((pos[0] - dx, pos[1] - dy))
            arrow.set_visible(math.hypot(wind[i], wind[j]) > 0.05)
            label.set_text(f"wind {speed:.1f} m/s")
        phi, theta, psi = np.degrees(np.asarray(frame.euler, float).reshape(3))
        psi = (psi + 180.0) % 360.0 - 180.0
        self._angles.set_text(f"roll {phi:+6.1f}\u00b0\npitch {theta:+6.1f}\u00b0\n"
                              f"yaw {psi:+7.1f}\u00b0")
        self._header.set_text(f"t = {frame.time:7.1f} s   T = {frame.tension / 1e3:6.2f} kN   "
                              f"L = {frame.length:6.1f} m   reel = {frame.reel_speed:+5.2f} m/s")

    def _ordered(self, art: dict) -> list:
        """Artists of one panel in drawing order (back to front)."""
        parts = [art["tether"], *art["fins"], art["hull"], art["trim"]]
        return sorted(parts, key=lambda a: a.get_zorder())  # stable: tether first

    def _blit(self, geo: dict) -> None:
        """Restore the background and draw the moving artists on the Agg canvas."""
        self._canvas.restore_region(self._background)
        for art in self._moving.values():
            for a in self._ordered(art):
                art["ax"].draw_artist(a)
        for key, (arrow, label, _) in self._wind.items():
            ax = self._ax_side if key == "side" else self._ax_top
            if arrow.get_visible():
                ax.draw_artist(arrow)
            ax.draw_artist(label)
        self._ax_close.draw_artist(self._angles)
        self._fig.draw_artist(self._header)

    def _show(self) -> None:
        """Redraw the window and wait one frame period."""
        import matplotlib.pyplot as plt

        self._canvas.draw_idle()
        self._canvas.flush_events()
        plt.pause(1.0 / self.fps)
        return None

    def _project(self, ax, xy: np.ndarray) -> tuple[int, int]:
        if self._fig is None or self._limits is None:
            raise RuntimeError("render a frame before projecting points")
        x, y = ax.transData.transform(xy)
        return int(math.floor(self.height - y)), int(math.floor(x))


def hull_pixel_center(renderer: Renderer, frame: Frame) -> tuple[int, int]:
    """Pixel (row, col) of the hull's axis mid-point in the side view of ``frame``.

    ``frame`` must be the frame last rendered (the limits are those of the last image).
    """
    e = np.asarray(frame.euler, float)
    R = np.asarray(rotation_matrix(e[0], e[1], e[2]))
    return renderer.project_side(np.asarray(frame.cm_pos, float) + R @ renderer.shape.centre)


def _fit_size(img: np.ndarray, height: int, width: int) -> np.ndarray:
    """Crop or edge-pad to exactly (height, width) (guards against a one-pixel rounding)."""
    img = img[:height, :width]
    dh, dw = height - img.shape[0], width - img.shape[1]
    if dh or dw:
        img = np.pad(img, ((0, dh), (0, dw), (0, 0)), mode="edge")
    return img


def _require_matplotlib() -> None:
    """The plot extra, as Gymnasium's DependencyNotInstalled (its environments' convention)."""
    try:
        require_plotting("rendering")
    except MissingExtraError as exc:  # pragma: no cover - matplotlib is in the plot/test extras
        from gymnasium.error import DependencyNotInstalled

        raise DependencyNotInstalled(str(exc)) from None
