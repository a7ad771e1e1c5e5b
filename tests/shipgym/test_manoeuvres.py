"""Manoeuvre figures against closed forms (turning circle) and the CLI's JSON shape."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from shipgym.manoeuvres import ManoeuvreError, turning_circle, zigzag
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params
from shipgym_baselines.cli import main


def test_nomoto2_steady_turn_matches_the_closed_form() -> None:
    """Steady state of eq. (1): r + β r³ = K δ + d0; diameter 2 u0 / r; no speed loss."""
    p = Nomoto2Params()
    delta = math.radians(20.0)
    r_ss = brentq(lambda r: r + p.beta * r**3 - p.K * delta - p.d0, 0.0, 2.0)
    _, fig = turning_circle(Nomoto2(p), 20.0)
    assert fig["steady_turn_rate"] == pytest.approx(math.degrees(r_ss), rel=1e-4)
    assert fig["steady_diameter"] == pytest.approx(2 * p.u0 / r_ss, rel=1e-4)
    assert fig["speed_loss"] == pytest.approx(0.0, abs=1e-5)
    # a kinematic ship turning at r_ss from straight ahead: transfer at 180° ≈ diameter
    assert fig["tactical_diameter"] == pytest.approx(2 * p.u0 / r_ss, rel=0.1)
    assert fig["t_90"] < fig["t_180"]


def test_zigzag_overshoot_grows_with_the_ship_time_constant() -> None:
    """A slower ship (larger T1) overshoots more in the same 20/20 zig-zag."""
    fast = zigzag(Nomoto2(Nomoto2Params(T1=1.0, d0=0.0)), 20.0)[1]
    slow = zigzag(Nomoto2(Nomoto2Params(T1=3.0, d0=0.0)), 20.0)[1]
    assert 0 < fast["overshoot_1"] < slow["overshoot_1"]
    assert fast["period"] < slow["period"]


def test_manoeuvre_log_holds_every_state() -> None:
    log, _ = zigzag(Nomoto2(), 10.0)
    assert log.states.shape == (log.t.size, 6)
    np.testing.assert_array_equal(log.states[:, 2], log.psi)


def test_cli_manoeuvre_json(tmp_path, capsys) -> None:
    assert main(["manoeuvre", "nomoto2", "turning", "--json", "--out", str(tmp_path)]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert {"advance", "transfer", "tactical_diameter", "steady_turn_rate"} <= set(figures)
    assert (tmp_path / "nomoto2_turning.png").is_file()
    assert main(["manoeuvre", "nomoto2", "zigzag", "--json", "--out", str(tmp_path)]) == 0
    assert {"overshoot_1", "overshoot_2"} <= set(json.loads(capsys.readouterr().out))
    assert main(["manoeuvre", "titanic", "zigzag"]) == 2
    assert "unknown ship" in capsys.readouterr().err


def test_a_rudder_beyond_the_limit_is_an_error_not_clipped() -> None:
    """nomoto2 steers ±30°: 35° would be a different manoeuvre than the figures claim."""
    model = Nomoto2()
    for run in (lambda d: turning_circle(model, d), lambda d: zigzag(model, d)):
        with pytest.raises(ManoeuvreError, match=r"rudder -?35\.0° is beyond .* ±30°"):
            run(35.0)
        with pytest.raises(ManoeuvreError, match="beyond"):
            run(-35.0)
    _, at_limit = turning_circle(model, 30.0)
    _, default = turning_circle(model)  # 35° or the ship's smaller limit
    assert default == at_limit


def test_the_figures_title_fits_the_figure() -> None:
    """The turning circle's nine figures in lines of at most 48 characters, each figure
    whole, and the rendered title inside the figure (no "tactical_dia…" cut)."""
    from shipgym.manoeuvres import TITLE_LINE_CHARS, figures_title, manoeuvre_figure

    model = Nomoto2()
    log, figures = turning_circle(model, 20.0)
    title = figures_title(figures)
    assert all(len(line) <= TITLE_LINE_CHARS for line in title.splitlines())
    assert title.replace("\n", " ").count(",") == len(figures) - 1
    assert "tactical_diameter " in title and "speed_loss " in title
    fig = manoeuvre_figure(model, "turning", log, figures)
    try:
        renderer = fig.canvas.get_renderer()
        box = fig.axes[1].title.get_window_extent(renderer)
        assert fig.axes[1].get_title() == title
        assert 0 <= box.x0 and box.x1 <= fig.bbox.width and box.y1 <= fig.bbox.height
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_the_rudder_help_says_the_turning_default_is_limited(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with pytest.raises(SystemExit):
        main(["manoeuvre", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "35 turning, limited to the ship's maximum rudder; 20 zig-zag" in text
