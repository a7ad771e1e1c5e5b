"""Xu & Guedes Soares (2020): the numbers the paper prints (§5.2, Tables 2–3)."""

from __future__ import annotations

#: Xu & Guedes Soares (2020) §5.2: identified 2nd-order Nomoto model (model scale)
PUBLISHED_NOMOTO = {"K": 0.185, "T1": 7.8569, "T2": 0.3815, "T3": 0.5297}
#: §5.2: "the control parameters ... are 212.6 and 547.8" — the A = B = 3 design (Kd, Kp)
PUBLISHED_GAINS = {"A=B=3": {"kp": 547.8, "kd": 212.6}}
#: Tables 2 (straight) and 3 (curved): (mean, std) of cross-track error [m], heading error
#: [deg] and rudder [deg]
PUBLISHED = {
    ("straight", "pid_lookahead_los"): {
        "cross_track": (0.64, 0.96),
        "heading_error": (1.13, 3.26),
        "rudder": (4.61, 7.78),
    },
    ("straight", "pid_vf"): {
        "cross_track": (0.53, 0.95),
        "heading_error": (1.25, 3.67),
        "rudder": (5.32, 8.90),
    },
    ("curved", "pid_lookahead_los"): {
        "cross_track": (0.40, 0.51),
        "heading_error": (0.32, 1.96),
        "rudder": (0.88, 4.14),
    },
    ("curved", "pid_vf"): {
        "cross_track": (0.42, 0.47),
        "heading_error": (0.37, 2.12),
        "rudder": (0.88, 0.91),
    },
}
#: the lines of Tables 2–3, each in both readings (module doc): (quantity, metric of the
#: mean, metric of the std, unit, reading)
TABLE_LINES = (
    ("cross-track error", "mean_cross_track", "std_cross_track", "m", "e"),
    ("cross-track error", "mean_abs_cross_track", "std_abs_cross_track", "m", "|e|"),
    ("heading error", "mean_heading_error_deg", "std_heading_error_deg", "deg", "ψd − ψ"),
    (
        "heading error",
        "mean_abs_heading_error_deg",
        "std_abs_heading_error_deg",
        "deg",
        "|ψd − ψ|",
    ),
    ("rudder", "mean_rudder_deg", "std_rudder_deg", "deg", "δ"),
    ("rudder", "mean_abs_rudder_deg", "std_abs_rudder_deg", "deg", "|δ|"),
)
