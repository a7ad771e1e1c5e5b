"""An episode as an animation file (GIF through Pillow; MP4 through ffmpeg, which the
``video`` extra's imageio-ffmpeg ships): the path, the track so far, the ship's outline, and
the cross-track error and rudder angle up to the frame's time."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.errors import ShipgymError
from shipgym.rendering import ship_outline

#: file suffix → what writes it
VIDEO_FORMATS = (".gif", ".mp4")
#: frames per second of the file
VIDEO_FPS = 10
#: most frames of a file (a longer episode is shown every k-th step)
MAX_FRAMES = 200
#: the trajectory arrays an animation reads
TRAJECTORY_KEYS = ("t", "x", "y", "heading", "cross_track_error", "rudder_angle")


class VideoError(ShipgymError, ValueError):
    """A video cannot be written: an unknown suffix, no ffmpeg for MP4, an episode without
    its trajectory."""


def check_video_file(file: str | os.PathLike) -> Path:
    """``file`` as a Path if its suffix is a format :func:`animate_episode` writes and, for
    MP4, ffmpeg is found (imageio-ffmpeg: ``pip install 'shipgym[video]'``), before any
    episode runs; else a :class:`VideoError` naming it."""
    path = Path(file)
    if path.suffix.lower() not in VIDEO_FORMATS:
        raise VideoError(
            f"--video {str(file)!r}: unknown format {path.suffix or '(no suffix)'!r}; "
            f"valid: {', '.join(VIDEO_FORMATS)}"
        )
    if path.suffix.lower() == ".mp4":
        ffmpeg_exe()
    return path


def ffmpeg_exe() -> str:
    """The ffmpeg binary imageio-ffmpeg ships (the ``video`` extra)."""
    try:
        import imageio_ffmpeg
    except ImportError as exc:
        raise VideoError(
            "an MP4 needs ffmpeg: pip install 'shipgym[video]' (imageio-ffmpeg), or write a .gif"
        ) from exc
    return imageio_ffmpeg.get_ffmpeg_exe()


def frame_indices(n_steps: int, max_frames: int = MAX_FRAMES) -> np.ndarray:
    """The samples shown: every k-th of ``n_steps`` and the last (k the smallest giving
    at most ``max_frames`` ≥ 2 in all)."""
    if max_frames < 2:
        raise VideoError(f"an animation has at least 2 frames, got max_frames={max_frames}")
    stride = max(1, math.ceil((n_steps - 1) / (max_frames - 1)))
    idx = np.arange(0, n_steps, stride)
    return idx if idx[-1] == n_steps - 1 else np.append(idx, n_steps - 1)


def animate_episode(
    trajectory: Mapping[str, Any],
    path_xy: np.ndarray,
    ship_length: float,
    file: str | os.PathLike,
    title: str = "",
    fps: int = VIDEO_FPS,
    max_frames: int = MAX_FRAMES,
) -> int:
    """Write the episode ``trajectory`` (arrays ``t`` [s], ``x``, ``y`` [m], ``heading``,
    ``rudder_angle`` [rad], ``cross_track_error`` [m]) over the path ``path_xy`` (n, 2) [m]
    as ``file`` (.gif or .mp4, :func:`check_video_file`); return the number of frames."""
    target = check_video_file(file)
    missing = [k for k in TRAJECTORY_KEYS if k not in trajectory]
    if missing:
        raise VideoError(f"the episode kept no trajectory arrays {missing}: nothing to animate")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter

    tr = {k: np.asarray(trajectory[k], dtype=float) for k in TRAJECTORY_KEYS}
    frames = frame_indices(len(tr["t"]), max_frames)
    fig, (ax, ax_e, ax_d) = plt.subplots(
        1, 3, figsize=(12, 4), dpi=80, gridspec_kw={"width_ratios": [1.4, 1, 1]}
    )
    ax.plot(path_xy[:, 0], path_xy[:, 1], "k--", lw=1, label="path")
    (track,) = ax.plot([], [], lw=1.2, color="C0", label="track")
    hull = ax.fill([], [], color="C1", alpha=0.8)[0]
    pad = 2.0 * ship_length
    xs, ys = np.concatenate([path_xy[:, 0], tr["x"]]), np.concatenate([path_xy[:, 1], tr["y"]])
    ax.set(xlim=(xs.min() - pad, xs.max() + pad), ylim=(ys.min() - pad, ys.max() + pad))
    ax.set(xlabel="x [m]", ylabel="y [m]", title=title)
    ax.set_aspect("equal", adjustable="box")
    ax.legend(fontsize=7, loc="best")
    (err,) = ax_e.plot([], [], lw=1)
    (rud,) = ax_d.plot([], [], lw=1, color="C2")
    t = tr["t"]
    rudder = np.degrees(tr["rudder_angle"])
    for axis, values, label in (
        (ax_e, tr["cross_track_error"], "e [m]"),
        (ax_d, rudder, "δ [deg]"),
    ):
        span = float(np.ptp(values)) or 1.0
        axis.set(xlim=(t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0), xlabel="t [s]", ylabel=label)
        axis.set_ylim(values.min() - 0.05 * span, values.max() + 0.05 * span)
    fig.tight_layout()

    def draw(k: int) -> tuple[Any, ...]:
        i = frames[k] + 1
        track.set_data(tr["x"][:i], tr["y"][:i])
        hull.set_xy(ship_outline(tr["x"][i - 1], tr["y"][i - 1], tr["heading"][i - 1], ship_length))
        err.set_data(t[:i], tr["cross_track_error"][:i])
        rud.set_data(t[:i], rudder[:i])
        return track, hull, err, rud

    animation = FuncAnimation(fig, draw, frames=len(frames), blit=False)
    if target.suffix.lower() == ".mp4":
        matplotlib.rcParams["animation.ffmpeg_path"] = ffmpeg_exe()
        writer: Any = FFMpegWriter(fps=fps)
    else:
        writer = PillowWriter(fps=fps)
    target.parent.mkdir(parents=True, exist_ok=True)
    try:
        animation.save(str(target), writer=writer)
    finally:
        plt.close(fig)
    return len(frames)
