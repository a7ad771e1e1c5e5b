"""The change families: what changes during a scenario, each family registered once.

A scenario file names its family with its ``family:`` key
(:class:`~shipgym.scenarios.schema.ScenarioConfig`, checked against :data:`FAMILIES`).  The
leaderboard's headroom and change-share tables group the scenarios by it, in the order of
:data:`FAMILIES`, and title each family with its ``label``.

What makes a family is the part of the plant its change moves (``targets``, each one of
:data:`TARGETS`): the change is a parameter event (``events:``) or a current appearing (a
``two_phase`` current of ``disturbances:``).  A scenario of a family moves only its targets
(tested on the catalogue).  A file without ``family:`` is of the family :data:`OTHER`.
"""

from __future__ import annotations

from dataclasses import dataclass

#: what a change can move: the steering gear (the servo time constant and the rudder rate,
#: the ``servo`` and ``rate`` quantities of :data:`shipgym.identification.adaptation.QUANTITIES`),
#: nomoto2's current-induced yaw bias ``d0``, the current (a ``two_phase`` current) and the
#: hull (any other parameter: the manoeuvring coefficients, a loading change's derivatives)
TARGETS = ("steering_gear", "yaw_bias", "current", "hull")


@dataclass(frozen=True)
class ChangeFamily:
    """One change family: ``name`` (a scenario file's ``family:`` value), ``label`` (how
    tables and figures title it), ``changes`` (what changes, in words) and ``targets`` (what
    its change may move, :data:`TARGETS`; empty: nothing changes; None: anything)."""

    name: str
    label: str
    changes: str
    targets: frozenset[str] | None


#: the family of the scenarios without a change
NOMINAL = "nominal"
#: the family of a scenario in none of the others (a paper's case, a sampled scenario, a
#: file without ``family:``)
OTHER = "other"

#: every change family by name, in the order the tables show them
FAMILIES: dict[str, ChangeFamily] = {
    family.name: family
    for family in (
        ChangeFamily(NOMINAL, "nominal", "nothing: the ship as designed throughout", frozenset()),
        ChangeFamily(
            "rudder_aging",
            "rudder aging",
            "the steering gear slows: a longer servo time constant and a lower rudder rate",
            frozenset({"steering_gear"}),
        ),
        ChangeFamily(
            "current_shift",
            "current shift",
            "a current appears across the route (nomoto2: its yaw bias d0 shifts)",
            frozenset({"current", "yaw_bias"}),
        ),
        ChangeFamily(
            "maneuverability_change",
            "maneuverability change",
            "the hull's manoeuvring: a loading change (draught) on the 3-DOF ships, every "
            "parameter at once on nomoto2 (Liu et al. 2019, Case 3)",
            frozenset({"hull", "steering_gear", "yaw_bias"}),
        ),
        ChangeFamily(
            OTHER,
            "other",
            "anything else: a paper's case (waves, a constant or stochastic current), a "
            "sampled scenario",
            None,
        ),
    )
}
#: the families whose scenarios have a change, in table order
CHANGES = tuple(name for name, family in FAMILIES.items() if family.targets)


def check_family(name: str) -> str:
    """``name`` if it is a registered family (:data:`FAMILIES`), else a ValueError naming
    it and the valid ones."""
    if name not in FAMILIES:
        raise ValueError(f"unknown change family {name!r}; valid: {', '.join(FAMILIES)}")
    return name


def family_label(name: str) -> str:
    """How tables and figures title the family ``name`` (:data:`FAMILIES`)."""
    return FAMILIES[check_family(name)].label
