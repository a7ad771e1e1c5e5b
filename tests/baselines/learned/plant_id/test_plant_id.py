"""The learned estimator's pieces: labels that invert to the truth, features that are the
same in training and acting, and a controller that reads no truth."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import shipgym  # noqa: F401  (registers the envs)
from shipgym.envs.context import ControllerContext
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.envs.truth import PlantTruth
from shipgym.scenarios.loader import load_scenario
from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import run_episode
from shipgym_baselines.learned.plant_id.controller import NmpcLearnedId
from shipgym_baselines.learned.plant_id.features import Window, episode_windows, step_row
from shipgym_baselines.learned.plant_id.labels import SLOTS, Labeller, plant_of, slot_mask
from shipgym_baselines.learned.plant_id.network import Estimator, build
from shipgym_baselines.learned.plant_id.shipped import shipped_seeds
from shipgym_baselines.records.manifest import check_listed, read_manifest
from shipgym_baselines.registry import make_controller, resolve_controller
from shipgym_baselines.training.plant_id import rollout, windows

torch = pytest.importorskip("torch")


def _context(name: str) -> tuple[ControllerContext, Any]:
    scenario = load_scenario(name)
    return ControllerContext.of(scenario, "rudder"), scenario


@pytest.mark.parametrize(
    ("scenario", "slot", "value"),
    [
        ("esso_osaka_maneuverability_change", "draught", math.log(0.4)),
        ("mariner_maneuverability_change", "draught", math.log(1.3)),
        ("blanke_rudder_aging", "servo", math.log(3.0)),
        ("rudder_aging", "servo", math.log(10.0)),
    ],
)
def test_the_labels_of_a_catalogue_change_are_its_size(
    scenario: str, slot: str, value: float
) -> None:
    """After the change the label of its quantity is its size, the other quantity slots 0
    where the change moves nothing else (1e-4: the catalogue prints its loading changes to
    5 digits); the labels give the true parameter vector back (plant_of, 1e-3 relative)."""
    ctx, sc = _context(scenario)
    after = sc.schedule.record_at(sc.config.time_limit)
    truth = PlantTruth(t=0.0, state=np.zeros(1), params=after, disturbance_now=np.zeros(3))
    labeller = Labeller(ctx)
    labels = labeller(truth)
    assert labels[SLOTS.index(slot)] == pytest.approx(value, abs=1e-4)
    names = labeller.adaptation.names
    moved_rate = "rate" in names and not math.isclose(
        after.as_dict()[labeller.adaptation.quantities[names.index("rate")].params[0]],
        ctx.nominal_params.as_dict()[labeller.adaptation.quantities[names.index("rate")].params[0]],
    )
    for other in names:
        if other != slot and not (other == "rate" and moved_rate):
            assert labels[SLOTS.index(other)] == pytest.approx(0.0, abs=1e-4), other
    theta, w = plant_of(ctx, labeller.adaptation, labels, labeller.bias_scale)
    np.testing.assert_allclose(theta, after.to_vector(), rtol=1e-3)
    np.testing.assert_allclose(w, 0.0, atol=1e-12)


def test_nomoto2_d0_shift_is_its_yaw_bias() -> None:
    """current_shift on nomoto2 moves d0, which enters as the yaw bias does: the bias label
    is the shift over the full-rudder bias, and plant_of puts it in yaw_disturbance."""
    ctx, sc = _context("current_shift")
    after = sc.schedule.record_at(sc.config.time_limit)
    truth = PlantTruth(t=0.0, state=np.zeros(1), params=after, disturbance_now=np.zeros(3))
    labeller = Labeller(ctx)
    labels = labeller(truth)
    shift = after.d0 - ctx.nominal_params.d0
    assert labels[SLOTS.index("bias")] == pytest.approx(shift / labeller.bias_scale, rel=1e-9)
    _, w = plant_of(ctx, labeller.adaptation, labels, labeller.bias_scale)
    assert w[2] == pytest.approx(shift, rel=1e-9)


def test_every_adapted_quantity_has_a_slot() -> None:
    from shipgym.identification.adaptation import QUANTITIES
    from shipgym_baselines.learned.plant_id.labels import QUANTITY_SLOTS

    assert {q.name for qs in QUANTITIES.values() for q in qs} == set(QUANTITY_SLOTS)


def test_a_ship_has_its_own_slots() -> None:
    assert slot_mask("nomoto2")[SLOTS.index("gain")] == 1.0
    assert slot_mask("nomoto2")[SLOTS.index("draught")] == 0.0
    assert slot_mask("mariner")[SLOTS.index("draught")] == 1.0
    assert all(slot_mask(s)[SLOTS.index("bias")] == 1.0 for s in ("nomoto2", "kvlcc2"))


def test_a_straight_run_reads_as_cruise_over_ground() -> None:
    """A ship that moved U0·Ts along its heading: surge over ground 1, sway 0."""
    ctx, _ = _context("nominal")
    u, ts, psi = ctx.nominal_speed, ctx.control_period, 0.3
    before = {
        "heading": psi,
        "yaw_rate": 0.0,
        "rudder_angle": 0.0,
        "rudder_command": 0.0,
        "position": (1.0, 2.0),
    }
    after = {**before, "position": (1.0 + u * ts * math.cos(psi), 2.0 + u * ts * math.sin(psi))}
    row = step_row(after, before, ctx)
    assert row[5] == pytest.approx(1.0, rel=1e-12) and row[6] == pytest.approx(0.0, abs=1e-12)
    assert np.all(step_row(before, None, ctx)[3:7] == 0.0)


def _tiny_estimator(folder: Path, inputs: int) -> Path:
    net = build(inputs, len(SLOTS), seed=0)
    meta = {"inputs": inputs, "outputs": len(SLOTS), "slots": list(SLOTS), "window": 32}
    Estimator(net, np.zeros(inputs, np.float32), np.ones(inputs, np.float32), meta).save(folder)
    return folder


def test_training_windows_are_the_acting_windows(tmp_path: Path) -> None:
    """The windows training builds from an episode's rows are, row by row, the inputs the
    controller's Window gives at each step of the same episode."""
    scenario = load_scenario("rudder_aging")
    policy, _ = make_controller("pid_los")
    data = rollout(scenario, policy, seed=10_000)
    data["starts"] = np.array([0])
    ctx = ControllerContext.of(scenario, "rudder")
    acting = episode_windows(data["rows"], ctx.feature_row)
    np.testing.assert_array_equal(windows(data, np.arange(len(data["rows"]))), acting)
    env = ShipPathFollowEnv(scenario)
    obs, info = env.reset(seed=10_000)
    policy.reset(ctx, seed=10_000)
    window = Window(ctx)
    window.add(info)
    np.testing.assert_allclose(window.input(), acting[0], rtol=1e-6)
    obs, *_, info = env.step(policy.act(obs, info))
    window.add(info)
    np.testing.assert_allclose(window.input(), acting[1], rtol=1e-6)


def test_the_learned_controller_reads_no_truth(tmp_path: Path, truth_calls: list[str]) -> None:
    """nmpc_learned_id (any φ) plays without a call of the privileged channel or the env's
    truth; it is a learned row."""
    folder = _tiny_estimator(tmp_path / "phi", 32 * 9 + 7)
    assert resolve_controller("nmpc_learned_id").kind == "learned"
    calls = truth_calls
    policy = NmpcLearnedId(folder=folder)
    result = run_episode(policy, load_scenario("rudder_aging"), seed=10_000)
    assert calls == []
    assert np.isfinite(result.metrics["cost"])


def test_training_writes_its_rounds_and_resumes_without_collecting_again(tmp_path: Path) -> None:
    """A tiny run: per round its data and φ, the error curve and data cost in the final
    meta; a resumed run whose last φ was lost refits it from the kept data (no new
    episodes: the shards are untouched) and a finished run resumed trains nothing."""
    from shipgym_baselines.training import plant_id as trainer

    out = tmp_path / "phi"
    kwargs = dict(
        first=2, later=1, rounds=2, updates=5, later_updates=3, workers=1, validation_trials=1
    )
    meta = trainer.train(0, out, False, **kwargs)
    assert [c["round"] for c in meta["error_curve"]] == [0, 1]
    assert set(meta["error_curve"][0]["validation_rmse"]) == set(SLOTS)
    assert [c["episodes"] for c in meta["data_cost"]] == [2, 1]
    assert meta["data_cost"][1]["behaviour"] == "nmpc_learned_id"
    shards = {p.name: p.stat().st_mtime_ns for p in (out / "data").iterdir()}
    with pytest.raises(RunError, match="is not empty"):
        trainer.train(0, out, False, **kwargs)
    assert check_listed(out) <= read_manifest(out)  # every file the run wrote, listed
    (out / "notes.txt").symlink_to(tmp_path / "mine.txt")  # a run writes through no link
    with pytest.raises(RunError, match=r"notes\.txt is a symbolic link"):
        trainer.train(0, out, True, **kwargs)
    (out / "notes.txt").unlink()
    import shutil

    shutil.rmtree(out / "round_001")
    again = trainer.train(0, out, True, **kwargs)
    assert {p.name: p.stat().st_mtime_ns for p in (out / "data").iterdir()} == shards
    assert again["error_curve"][0] == meta["error_curve"][0]
    assert (out / "estimator" / "estimator.pt").is_file()
    policy = NmpcLearnedId(folder=out / "estimator")
    assert policy.estimator.meta["round"] == 1


@pytest.mark.skipif(len(shipped_seeds()) < 2, reason="needs two shipped seeds")
def test_dealt_trials_are_each_seeds_own_episode() -> None:
    """A shared-trials row deals its trials among the shipped estimators: each dealt
    episode is the one its training seed plays alone (lockstep changes nothing), labelled
    with that seed."""
    from shipgym_baselines.evaluation import evaluate_batch

    first, second = shipped_seeds()[:2]
    seeds = [10_000, 10_001]
    dealt = evaluate_batch("nmpc_learned_id", "rudder_aging", seeds, training_seeds=[first, second])
    alone = [
        run_episode(NmpcLearnedId(training_seed=k), load_scenario("rudder_aging"), seed=s)
        for k, s in zip((first, second), seeds, strict=True)
    ]
    assert [r.training_seed for r in dealt] == [first, second]
    assert [r.metrics["cost"] for r in dealt] == [r.metrics["cost"] for r in alone]


def test_the_fallback_reads_the_ships_chosen_spreads_under_the_given_ones(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from shipgym_baselines.learned.plant_id import controller as module

    chosen = {"mariner": {"prior_std": 2.0, "fit_std": 0.3}}
    monkeypatch.setattr(module, "tuned_settings", lambda name, ship: dict(chosen.get(ship, {})))
    tuned = NmpcLearnedId()
    assert tuned.fallback_settings("mariner") == {"prior_std": 2.0, "fit_std": 0.3}
    assert tuned.fallback_settings("blanke") == module.FALLBACK_DEFAULTS  # none chosen
    given = NmpcLearnedId(fit_std=0.05)
    assert given.fallback_settings("mariner") == {"prior_std": 2.0, "fit_std": 0.05}
    default = NmpcLearnedId(preset="default")
    assert default.fallback_settings("mariner") == module.FALLBACK_DEFAULTS
    with pytest.raises(ValueError, match="prior_std must be > 0"):
        NmpcLearnedId(prior_std=0.0)
    with pytest.raises(ValueError, match="preset must be"):
        NmpcLearnedId(preset="paper")


def test_the_shipped_chosen_spreads_reach_the_fallback_at_reset() -> None:
    """The packaged chosen file: nomoto2 and the Esso Osaka have tuned sections, the Mariner
    and the Blanke vessel kept the settings before tuning; reset reads the ship's own."""
    from shipgym_baselines.learned.plant_id import controller as module
    from shipgym_baselines.records.chosen import tuned_settings

    policy = NmpcLearnedId()
    for ship in ("mariner", "blanke"):
        assert tuned_settings("nmpc_learned_id", ship) == {}
        assert policy.fallback_settings(ship) == module.FALLBACK_DEFAULTS
    for ship in ("nomoto2", "esso_osaka"):
        chosen = tuned_settings("nmpc_learned_id", ship)
        assert set(chosen) == set(module.FALLBACK_DEFAULTS)
        assert chosen != module.FALLBACK_DEFAULTS
    env = ShipPathFollowEnv(load_scenario("rudder_aging"))  # nomoto2
    env.reset(seed=0)
    policy.reset(env.controller_context)
    chosen = tuned_settings("nmpc_learned_id", "nomoto2")
    assert policy.prior_var == pytest.approx(chosen["prior_std"] ** 2)
    assert policy.fit_var == pytest.approx(chosen["fit_std"] ** 2)
    env.close()


def test_a_chosen_file_with_an_unknown_or_empty_spread_is_named(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from shipgym_baselines.learned.plant_id import controller as module

    for bad, match in (({"prior_sd": 1.0}, "prior_sd"), ({"fit_std": None}, "fit_std")):
        monkeypatch.setattr(module, "tuned_settings", lambda name, ship, bad=bad: dict(bad))
        with pytest.raises(ValueError, match=match):
            NmpcLearnedId().fallback_settings("mariner")
