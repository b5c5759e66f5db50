"""Matplotlib renderer (aerostat_gym.envs.render): image format, hull placement, figure reuse
and mode validation. Frames come from the baseline trim at U = 10 m/s; no simulation runs.
"""

import dataclasses
import warnings

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import matplotlib.image as mpimg  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402

from aerostat_gym.analysis.trim import find_equilibrium  # noqa: E402
from aerostat_gym.envs.render import (  # noqa: E402
    HULL_COLOR,
    RENDER_MODES,
    Frame,
    Renderer,
    hull_pixel_center,
)
from aerostat_gym.params import load_params  # noqa: E402
from aerostat_gym.physics.state import StateLayout  # noqa: E402
from aerostat_gym.sim import Model  # noqa: E402

HULL_RGB = np.array([round(255 * c) for c in to_rgb(HULL_COLOR)])
COLOR_TOL = 6  # per channel: interior pixels of a filled polygon are exact in Agg (+-1 rounding)


@pytest.fixture(scope="module")
def params():
    return load_params()


@pytest.fixture(scope="module")
def frame(params):
    """The trim at 10 m/s along +X (aerostat about 22 m downwind, 312 m up)."""
    eq = find_equilibrium(params, wind_speed=10.0)
    model = Model(params)
    lay = StateLayout(params.tether.n_elements)
    x = eq.x
    return Frame(time=0.0, nodes=model.node_positions(x), cm_pos=x[lay.cm_pos].copy(),
                 euler=x[lay.euler].copy(), wind=np.array([10.0, 0.0, 0.0]),
                 tension=model.end_tensions(x)[1], length=float(x[lay.winch_length]),
                 reel_speed=0.0)


def shifted(frame, dx):
    """The same frame with the aerostat and the tether moved by dx metres along X."""
    d = np.array([dx, 0.0, 0.0])
    return dataclasses.replace(frame, nodes=frame.nodes + d, cm_pos=frame.cm_pos + d)


def is_hull(img, rc):
    return bool(np.all(np.abs(img[rc].astype(int) - HULL_RGB) <= COLOR_TOL))


def test_rgb_array_format(params, frame, tmp_path):
    for width, height in ((800, 480), (641, 363)):
        r = Renderer(params, "rgb_array", width=width, height=height)
        img = r.render(frame)
        assert img.dtype == np.uint8 and img.shape == (height, width, 3)
        assert img.flags["C_CONTIGUOUS"]
        assert img.min() < 100 and img.max() == 255  # something drawn on a white figure
        path = tmp_path / f"frame_{width}x{height}.png"
        mpimg.imsave(path, img)
        back = mpimg.imread(path)
        assert back.shape[:2] == (height, width)
        r.close()
        assert r.figure is None


def test_hull_drawn_where_the_state_says(params, frame):
    r = Renderer(params, "rgb_array")
    img = r.render(frame)
    # the CM lies inside the hull (0.72 m below its axis, radius 3.85 m, about 1 px/m): exact pixel
    cm_px = r.project_side(frame.cm_pos)
    assert is_hull(img, cm_px)
    assert abs(np.subtract(hull_pixel_center(r, frame), cm_px)).max() <= 3  # within 3 pixels
    # halfway down the tether there is no hull
    assert not is_hull(img, r.project_side(frame.nodes[len(frame.nodes) // 2]))
    # top view: the CM pixel is hull too (the upper fin may cover the axis, so look 1 m aside)
    img_top_px = r.project_top(frame.cm_pos + np.array([0.0, 1.5, 0.0]))
    assert is_hull(img, img_top_px)
    # move everything 30 m downwind (about 30 px, more than the 18 m hull): the hull follows
    moved = shifted(frame, 30.0)
    img2 = r.render(moved)
    new_px = r.project_side(moved.cm_pos)
    assert new_px[1] - cm_px[1] >= 20
    assert is_hull(img2, new_px)
    assert not is_hull(img2, cm_px)
    r.close()


def test_trim_marker_and_zero_wind(params, frame):
    r = Renderer(params, "rgb_array")
    trim = frame.cm_pos + np.array([-40.0, 0.0, 0.0])  # 40 m upwind of the aerostat
    img = r.render(dataclasses.replace(frame, trim_cm=trim, wind=np.zeros(3)))
    row, col = r.project_side(trim)
    patch = img[row - 2:row + 3, col - 2:col + 3].astype(int)
    assert np.any(patch[..., 1] - patch[..., 0] > 60)  # the green cross within 2 pixels
    r.close()


def test_figure_reused(params, frame):
    r = Renderer(params, "rgb_array")
    r.render(frame)
    fig = r.figure
    counts = (len(fig.axes), [len(ax.get_children()) for ax in fig.axes], len(fig.texts))
    for k in range(20):
        f = dataclasses.replace(frame, time=0.1 * k, euler=frame.euler + 0.01 * k,
                                reel_speed=0.05 * k, tension=frame.tension + 10.0 * k)
        img = r.render(f)
    assert r.figure is fig  # one figure, updated in place: no artists pile up
    assert (len(fig.axes), [len(ax.get_children()) for ax in fig.axes], len(fig.texts)) == counts
    assert img.shape == (480, 800, 3)
    r.close()


def test_limits_grow_when_the_aerostat_leaves(params, frame):
    r = Renderer(params, "rgb_array")
    r.render(frame)
    far = shifted(frame, 400.0)  # beyond the initial downwind range (0.6 x 350 m)
    img = r.render(far)
    assert is_hull(img, r.project_side(far.cm_pos))
    r.close()


@pytest.mark.parametrize("mode", [None, "rgb", "ansi"])
def test_invalid_mode(params, mode):
    with pytest.raises(ValueError) as err:
        Renderer(params, mode)
    msg = str(err.value)
    assert repr(mode) in msg and all(m in msg for m in RENDER_MODES)


def test_human_without_display_falls_back(params, frame, monkeypatch):
    import matplotlib

    monkeypatch.setattr(matplotlib, "get_backend", lambda *a, **k: "agg")
    r = Renderer(params, "human")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert r.render(frame) is None
        assert r.render(frame) is None
    assert sum("interactive" in str(w.message) for w in caught) == 1  # one warning, no error
    r.close()
