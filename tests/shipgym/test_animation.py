"""An episode's animation: GIF through Pillow, MP4 through the video extra's
ffmpeg, gymnasium's RecordVideo through moviepy; clear errors before any work."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from shipgym.animation import VideoError, animate_episode, check_video_file, frame_indices
from shipgym_baselines.cli import main


def trajectory(n: int = 50) -> dict[str, np.ndarray]:
    """A ship turning onto the x axis from 2 m off it (rad, m, s)."""
    t = np.linspace(0.0, 49.0, n)
    e = 2.0 * np.exp(-t / 10.0)
    return {
        "t": t,
        "x": 1.0 * t,
        "y": e,
        "heading": -0.2 * np.exp(-t / 10.0),
        "cross_track_error": e,
        "rudder_angle": -0.05 * e,
    }


def test_frames_are_every_kth_step_and_the_last() -> None:
    assert frame_indices(10, 20).tolist() == list(range(10))
    assert frame_indices(10, 4).tolist() == [0, 3, 6, 9]
    idx = frame_indices(1001, 200)  # stride ceil(1001 / 200) = 6
    assert idx[0] == 0 and idx[-1] == 1000 and np.all(np.diff(idx)[:-1] == 6)
    assert len(idx) <= 201


def test_a_gif_has_one_frame_per_shown_step(tmp_path: Path) -> None:
    path = np.array([[0.0, 0.0], [50.0, 0.0]])
    file = tmp_path / "episode.gif"
    assert animate_episode(trajectory(), path, 1.0, file, "test", max_frames=5) == 5
    with Image.open(file) as gif:
        assert gif.format == "GIF" and gif.n_frames == 5


def test_an_mp4_through_the_video_extra(tmp_path: Path) -> None:
    pytest.importorskip("imageio_ffmpeg")
    file = tmp_path / "episode.mp4"
    path = np.array([[0.0, 0.0], [50.0, 0.0]])
    assert animate_episode(trajectory(), path, 1.0, file, max_frames=4) == 4
    assert file.read_bytes()[4:8] == b"ftyp"  # an MP4 container


def test_bad_video_files_are_named_before_any_episode(tmp_path: Path, capsys) -> None:
    with pytest.raises(VideoError, match=r"unknown format '\.avi'; valid: \.gif, \.mp4"):
        check_video_file("a.avi")
    with pytest.raises(VideoError, match=r"no trajectory arrays \['heading'"):
        no_heading = {k: v for k, v in trajectory().items() if k != "heading"}
        animate_episode(no_heading, np.zeros((2, 2)), 1.0, tmp_path / "a.gif")
    out = ["--out", str(tmp_path / "run"), "--video", str(tmp_path / "a.webm")]
    assert main(["run", "nominal", "pid_los", *out]) == 2
    assert "--video" in capsys.readouterr().err and not (tmp_path / "run").exists()


def test_record_video_works_with_the_video_extra(tmp_path: Path) -> None:
    """gymnasium.wrappers.RecordVideo needs moviepy (the ``video`` extra)."""
    pytest.importorskip("moviepy")
    import gymnasium as gym

    import shipgym  # noqa: F401  (registers the envs)

    env = gym.make("ShipPathFollow-v0", render_mode="rgb_array")
    env = gym.wrappers.RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda e: True)
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.zeros(env.action_space.shape, dtype=np.float32))
    env.close()
    (video,) = (tmp_path / "videos").glob("*.mp4")
    assert video.stat().st_size > 0
