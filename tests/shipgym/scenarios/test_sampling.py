"""Scenario distributions: every ship in training, its own jumps and timing, the splits."""

from __future__ import annotations

import collections
import itertools
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from shipgym.models import MODELS
from shipgym.models.loading import loading_change
from shipgym.scenarios.loader import ScenarioError, build_scenario, list_scenarios, load_scenario
from shipgym.scenarios.sampling import (
    DistributionConfig,
    DistributionError,
    ScenarioDistribution,
    load_distribution,
    train_rng,
)
from shipgym_baselines.evaluation import run_episode
from shipgym_baselines.registry import make_controller

SHIPS = ("nomoto2", "esso_osaka", "mariner", "blanke")
DISTRIBUTIONS = Path(__file__).resolve().parents[3] / "configs/distributions"


def _train_draws(n: int = 400) -> list[Any]:
    train = load_distribution("train")
    return [train.sample(train_rng(seed)) for seed in range(n)]


def _legs(waypoints: list[tuple[float, float]]) -> float:
    """Length of a polyline through the waypoints [m]."""
    return sum(math.dist(a, b) for a, b in itertools.pairwise(waypoints))


def _distribution(data: dict[str, Any]) -> ScenarioDistribution:
    return ScenarioDistribution(DistributionConfig.model_validate(data))


def _raw(name: str) -> dict[str, Any]:
    return yaml.safe_load((DISTRIBUTIONS / f"{name}.yaml").read_text())


def test_training_covers_every_ship_with_about_equal_env_steps() -> None:
    """All four ships are drawn; the weights give each ≈ a quarter of the env steps (the
    nominal steps of a route: its length / (U·Ts))."""
    steps: collections.Counter[str] = collections.Counter()
    for config in _train_draws():
        sc = build_scenario(config, config.name)
        route = _legs(config.path.waypoints)
        steps[config.ship.model] += route / (sc.model.nominal_speed * sc.control_period)
    assert set(steps) == set(SHIPS)
    shares = {ship: steps[ship] / sum(steps.values()) for ship in SHIPS}
    assert all(0.15 < share < 0.35 for share in shares.values()), shares


def test_a_sampled_scenario_has_its_ships_timing_scale_and_jumps() -> None:
    """Ts and h are the model's; waypoints scale with the ship length; each ship's jumps
    change its own parameters (nomoto2 d0 shift; a current appearing on the others)."""
    kinds: dict[str, set[str]] = collections.defaultdict(set)
    for config in _train_draws():
        sc = build_scenario(config, config.name)
        model = MODELS[config.ship.model]
        assert (sc.control_period, sc.fine_step) == (model.control_period, model.fine_step)
        first = np.array(config.path.waypoints[0])
        assert first[0] == pytest.approx(sc.model.length, rel=1e-3)  # 1 L ahead
        assert abs(first[1]) <= 3.0 * sc.model.length + 1e-3
        for event in config.events:
            assert set(event.params) <= set(model.params_type.names())
            kinds[config.ship.model].add(",".join(sorted(event.params)))
        if config.disturbances.current.kind == "two_phase":
            kinds[config.ship.model].add("current")
    loading = {
        ship: ",".join(sorted(loading_change(ship, MODELS[ship].params_type(), 0.8)))
        for ship in SHIPS[1:]
    }
    assert kinds["nomoto2"] == {"Tc", "d0", "K,T1"}
    assert kinds["esso_osaka"] == {"T_servo", "Nd,Yd", loading["esso_osaka"], "current"}
    assert kinds["mariner"] == {"T_delta", "a3", loading["mariner"], "current"}
    assert kinds["blanke"] == {"T_delta", "dCL", loading["blanke"], "current"}


def test_a_current_shift_is_a_calm_then_appearing_current_within_the_time_limit() -> None:
    shifts = [c for c in _train_draws() if c.disturbances.current.kind == "two_phase"]
    assert shifts
    for config in shifts:
        current = config.disturbances.current
        assert current.speed == 0.0 and current.sigma == 0.0
        assert 0.0 < current.second_speed < 0.5 * MODELS[config.ship.model]().nominal_speed
        assert current.switch_time < config.time_limit
        assert config.events == []


def test_time_limits_allow_for_the_current_against_the_route() -> None:
    """time limit ≥ time_factor · route / (U − current speed): a current never makes the
    route impossible in time."""
    train = load_distribution("train").config
    for config in _train_draws(200):
        ship = next(s for s in train.ships if s.model == config.ship.model)
        path = ship.path or train.path
        current = config.disturbances.current
        speed = max(current.speed, getattr(current, "second_speed", 0.0))
        model = build_scenario(config, config.name).model
        route = model.length + _legs(config.path.waypoints)  # + the 1 L approach
        limit = path.time_factor * route / (model.nominal_speed - speed) + ship.time_margin
        assert config.time_limit >= limit * (1 - 1e-4)


def test_linked_jump_moves_both_rudder_derivatives_by_one_factor() -> None:
    nominal = MODELS["esso_osaka"].params_type()
    seen = 0
    for config in _train_draws():
        for event in config.events:
            if "Yd" in event.params:
                base = config.ship.params
                assert event.params["Yd"] / base["Yd"] == pytest.approx(
                    event.params["Nd"] / base["Nd"], rel=1e-12
                )
                seen += 1
        if config.ship.model == "esso_osaka":
            # factors on parameters not listed start from the model's defaults
            assert 0.8 <= config.ship.params["Nr"] / nominal.Nr <= 1.25
    assert seen


def test_heldout_interleaves_the_ships_and_keeps_the_one_ship_scenarios() -> None:
    """heldout:0-3 are one scenario per ship; adding ships to a test split leaves the first
    ship's scenarios as they were (same seeds), only their names move."""
    heldout = load_distribution("heldout")
    assert len(heldout) == 24
    assert [heldout.test_scenario(i).ship.model for i in range(4)] == list(SHIPS)
    counts = collections.Counter(heldout.test_scenario(i).ship.model for i in range(24))
    assert counts == {"nomoto2": 12, "esso_osaka": 4, "mariner": 4, "blanke": 4}
    raw = _raw("heldout")
    one_ship = {**raw, "ships": [{**raw["ships"][0], "count": 4}]}
    alone = _distribution(one_ship)
    for j, index in enumerate([0, 4, 8, 12]):  # nomoto2's j-th scenario in the mixed split
        a, b = alone.test_scenario(j).model_dump(), heldout.test_scenario(index).model_dump()
        a.pop("name"), b.pop("name")
        if a["disturbances"]["current"]["speed"] == 0.0:
            assert a == b
        else:  # only the time limit may differ (U − current since the mixed split)
            assert {k for k in a if a[k] != b[k]} <= {"time_limit"}


#: per ship, the parameter whose factor measures each parameter family: servo
#: time constant (aging), the steering gain (gain), the loading change's key parameter
#: (loading: Esso Osaka's draught T, Blanke's mass, the Mariner's a3, the KVLCC2's volume)
AGING = {
    "nomoto2": "Tc",
    "esso_osaka": "T_servo",
    "mariner": "T_delta",
    "blanke": "T_delta",
    "kvlcc2": "T_servo",
}
GAIN = {"nomoto2": "K", "esso_osaka": "Yd", "mariner": "a3", "blanke": "dCL", "kvlcc2": "f_alpha"}
LOADING = {"esso_osaka": "T", "mariner": "a3", "blanke": "m", "kvlcc2": "volume"}
#: the suites' trial range of a current's speed factor (default and quick)
CURRENT_FACTOR = (0.8, 1.2)


def _base(config: Any, name: str) -> float:
    return config.ship.params.get(name, MODELS[config.ship.model].params_type().as_dict()[name])


def _families(config: Any) -> dict[str, tuple[float, float]]:
    """A scenario's changes: family → the interval of sizes its trials can take (a factor of
    the family's parameter; nomoto2's d0 shift in °/s; a current in m/s, × the trials'
    speed factor)."""
    ship = config.ship.model
    out: dict[str, tuple[float, float]] = {}
    for event in config.events:
        changed = set(event.params)
        if ship == "nomoto2" and changed == {"d0"}:
            shift = event.params["d0"] - config.ship.params["d0"]
            out["d0_shift"] = (shift, shift)
            continue
        if ship == "nomoto2" and len(changed) > 2:
            family, name = "case3", GAIN[ship]  # Liu et al. (2019) Case 3: all parameters
        elif AGING[ship] in changed:
            family, name = "aging", AGING[ship]
        elif ship in LOADING and (len(changed) > 2 or changed == {"a1", "a3"}):
            family, name = "loading", LOADING[ship]
        else:
            family, name = "gain", GAIN[ship]
        factor = event.params[name] / _base(config, name)
        out[family] = (factor, factor)
    current = config.disturbances.current
    if getattr(current, "second_speed", 0.0):
        lo, hi = CURRENT_FACTOR
        out["current"] = (current.second_speed * lo, current.second_speed * hi)
    return out


def _training_ranges(ship: Any) -> dict[str, tuple[float, float]]:
    """The documented (train.yaml) size range of each family of one ship, in the units of
    :func:`_families`."""
    kinds = ship.jumps.kinds
    model = ship.model
    out = {"aging": kinds["rudder_aging"].params[AGING[model]].range}
    out["gain"] = kinds["gain_change"].params[GAIN[model]].range
    if model == "nomoto2":
        out["d0_shift"] = kinds["current_shift"].params["d0"].range
        return out
    out["current"] = kinds["current_shift"].current.speed
    base = MODELS[model].params_type()
    ends = [
        loading_change(model, base, r)[LOADING[model]] / getattr(base, LOADING[model])
        for r in kinds["loading_change"].draught_ratio
    ]
    out["loading"] = (min(ends), max(ends))
    return out


def _tested_scenarios() -> list[Any]:
    """Every catalogue scenario with a change and every held-out scenario (configs)."""
    heldout = load_distribution("heldout")
    configs = [load_scenario(name).config for name in list_scenarios()]
    configs += [heldout.test_scenario(i) for i in range(len(heldout))]
    return [c for c in configs if _families(c)]


def test_heldout_other_ships_have_each_family_outside_training_and_a_combination() -> None:
    """order: cycle — the four held-out scenarios of each 3-DOF ship are rudder aging, a
    current shift, a loading change (each outside the training range) and aging + current."""
    heldout, train = load_distribution("heldout"), load_distribution("train").config
    for ship in SHIPS[1:]:
        ranges = _training_ranges(next(s for s in train.ships if s.model == ship))
        configs = [
            heldout.test_scenario(i)
            for i in range(len(heldout))
            if heldout.test_scenario(i).ship.model == ship
        ]
        seen = sorted(",".join(sorted(_families(c))) for c in configs)
        assert seen == ["aging", "aging,current", "current", "loading"], ship
        for config in configs:
            for family, (lo, hi) in _families(config).items():
                low, high = ranges[family]
                assert hi < low or lo > high, (ship, family)


def test_training_never_draws_a_catalogue_or_heldout_trial() -> None:
    """Every ship draws the three families within its documented training ranges, and
    those ranges are disjoint from the sizes of every catalogue and held-out scenario of
    that ship and family (a current × the suites' trial factor 0.8-1.2)."""
    train = load_distribution("train").config
    ranges = {ship.model: _training_ranges(ship) for ship in train.ships}
    drawn: dict[str, set[str]] = collections.defaultdict(set)
    for config in _train_draws(600):
        families = _families(config)
        assert len(families) <= 1, families  # one change per training episode
        for family, (lo, hi) in families.items():
            low, high = ranges[config.ship.model][family]
            factor = CURRENT_FACTOR if family == "current" else (1.0, 1.0)
            assert low * factor[0] - 1e-9 <= lo and hi <= high * factor[1] + 1e-9, family
            drawn[config.ship.model].add(family)
    assert drawn["nomoto2"] == {"aging", "d0_shift", "gain"}
    for ship in SHIPS[1:]:
        assert drawn[ship] == {"aging", "current", "gain", "loading"}, ship
    tested = _tested_scenarios()
    assert len(tested) > 40
    for config in tested:
        for family, (lo, hi) in _families(config).items():
            # a ship training never draws (kvlcc2, the unseen hull) is apart by construction
            trained = ranges.get(config.ship.model, {})
            low, high = trained.get(family, (math.inf, -math.inf))
            assert hi < low or lo > high, (config.name, family, (lo, hi), (low, high))


def test_validation_is_the_training_ranges_in_the_test_seed_space() -> None:
    validation, train = load_distribution("validation"), load_distribution("train")
    assert validation.split == "test" and len(validation) == 32
    assert validation.config.path == train.config.path
    for v, t in zip(validation.config.ships, train.config.ships, strict=True):
        assert v.count == 8 and v.jumps.order == "cycle"
        assert v.model_dump(exclude={"weight", "count", "jumps"}) == t.model_dump(
            exclude={"weight", "count", "jumps"}
        )
        assert v.jumps.probability == 1.0
        assert v.jumps.model_dump(exclude={"order", "probability"}) == t.jumps.model_dump(
            exclude={"order", "probability"}
        )
    assert [validation.test_scenario(i).ship.model for i in range(4)] == list(SHIPS)


def test_validation_covers_every_ship_and_family_inside_the_training_ranges() -> None:
    """The 32 validation trials: 8 per ship, each ship every family it is trained on (the
    three families: aging, a current / d0 shift, a manoeuvrability change — gain or
    loading), each size inside the documented training range, hence (by
    test_training_never_draws_a_catalogue_or_heldout_trial) apart from every catalogue and
    held-out scenario's."""
    validation, train = load_distribution("validation"), load_distribution("train").config
    ranges = {ship.model: _training_ranges(ship) for ship in train.ships}
    seen: dict[str, set[str]] = collections.defaultdict(set)
    per_ship: collections.Counter[str] = collections.Counter()
    for config in (validation.test_scenario(i) for i in range(len(validation))):
        per_ship[config.ship.model] += 1
        for family, (lo, hi) in _families(config).items():
            low, high = ranges[config.ship.model][family]
            factor = CURRENT_FACTOR if family == "current" else (1.0, 1.0)
            assert low * factor[0] - 1e-9 <= lo and hi <= high * factor[1] + 1e-9
            seen[config.ship.model].add(family)
    assert per_ship == dict.fromkeys(SHIPS, 8)
    assert seen["nomoto2"] == {"aging", "d0_shift", "gain"}
    for ship in SHIPS[1:]:
        assert seen[ship] == {"aging", "current", "gain", "loading"}, ship


def test_validation_seeds_are_apart_from_training_and_heldout() -> None:
    """Validation draws from the test seed space under its own name: its generators'
    entropy differs from the held-out split's and from every training scenario seed's (a
    different salt), and no validation trial equals a held-out or catalogue one."""
    import zlib

    from shipgym.scenarios.sampling import TEST_SALT, TRAIN_SALT

    assert TEST_SALT != TRAIN_SALT  # SeedSequence([salt, …]): training never meets test
    assert zlib.crc32(b"validation") != zlib.crc32(b"heldout")  # [TEST_SALT, crc32(name), j]
    validation, heldout = load_distribution("validation"), load_distribution("heldout")
    ours = {_content(validation.test_scenario(i)) for i in range(len(validation))}
    theirs = {_content(heldout.test_scenario(i)) for i in range(len(heldout))}
    theirs |= {_content(load_scenario(name).config) for name in list_scenarios()}
    assert len(ours) == 32 and not ours & theirs


def _content(config: Any) -> str:
    """A scenario's settings without its name and description."""
    data = config.model_dump(mode="json", exclude={"name", "description", "source"})
    return repr(sorted(data.items()))


def test_pid_los_finishes_every_validation_scenario() -> None:
    """Feasibility: every ship's in-range scenarios can be finished in their time limits
    (by pid_los as tuned on them)."""
    validation = load_distribution("validation")
    for name in validation.test_names():
        policy, mode = make_controller("pid_los")
        result = run_episode(policy, load_scenario(name), 0, mode)
        assert result.metrics["termination_reason"] == "goal", name


@pytest.mark.parametrize(
    ("edit", "key"),
    [
        (lambda d: d["ships"][1]["current"].update(speed=[0.0, 0.5]), "ships.1.current.speed"),
        (
            lambda d: d["ships"][2]["jumps"]["kinds"]["gain_change"]["params"]["a3"].update(
                range=[-1.0, 1.5]
            ),
            "ships.2.jumps.kinds.gain_change.params",
        ),
        (lambda d: d["ships"][0].update(count=3), "ships.0.count"),
        (lambda d: d["ships"][3]["jumps"].update(time=[27.0, 300.0]), "ships.3.jumps.time"),
        (lambda d: d["ships"][3]["jumps"].update(order="cycle"), "ships.3.jumps.order"),
        (lambda d: d["ships"][1]["param_factors"].update(Nx=[0.9, 1.1]), "param_factors.Nx"),
    ],
)
def test_bad_training_distribution_names_the_key(edit: Any, key: str, tmp_path: Path) -> None:
    data = _raw("train")
    edit(data)
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(DistributionError, match=key.replace(".", r"\.")):
        load_distribution(bad)


def test_a_test_split_with_several_ships_needs_their_counts(tmp_path: Path) -> None:
    data = _raw("heldout")
    del data["ships"][2]["count"]
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(DistributionError, match=r"ships\.2\.count"):
        load_distribution(bad)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("split: test\nranges_of: validation\ncount_per_ship: 1\n", "is not a train split"),
        ("split: train\nranges_of: train\ncount_per_ship: 1\n", "only a test split"),
        ("split: test\nranges_of: train\n", "count_per_ship"),
        ("split: test\nranges_of: train\ncount_per_ship: 1\npath: {}\n", "path: comes from"),
    ],
)
def test_ranges_of_takes_a_train_splits_ranges_only(
    text: str, message: str, tmp_path: Path
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\n" + text)
    with pytest.raises(DistributionError, match=message):
        load_distribution(bad)


# --- the in-range test split ------------------------------------------------------------------


def test_inrange_names_parse_and_generate_the_same_scenario_every_time() -> None:
    """``inrange:0`` … ``inrange:15``: four per ship, interleaved as the validation split,
    each name loading the same settings on every call; beyond 15 a clear error."""
    from shipgym.scenarios.sampling import sampled_scenario_config

    inrange = load_distribution("inrange")
    assert inrange.split == "test" and len(inrange) == 16
    assert inrange.test_names() == [f"inrange:{i}" for i in range(16)]
    assert [inrange.test_scenario(i).ship.model for i in range(16)] == list(SHIPS) * 4
    for name in ("inrange:0", "inrange:7", "inrange:15"):
        first = sampled_scenario_config(name)
        assert first.name == name
        assert first == sampled_scenario_config(name)
        assert load_scenario(name).config == first  # the env's loader reads the same
    with pytest.raises(DistributionError, match=r"index 16 out of range; valid: 0 … 15"):
        sampled_scenario_config("inrange:16")
    with pytest.raises(ScenarioError, match=r"inrange: index 16 out of range"):
        load_scenario("inrange:16")


def test_inrange_covers_every_ship_and_family_inside_the_training_ranges() -> None:
    """Every trial has its change, each size inside the training ranges (train.yaml); each
    3-DOF ship shows each of its four families once, nomoto2 its three."""
    inrange, train = load_distribution("inrange"), load_distribution("train").config
    assert inrange.config.ranges_of == "train" and inrange.config.path == train.path
    ranges = {ship.model: _training_ranges(ship) for ship in train.ships}
    seen: dict[str, list[str]] = collections.defaultdict(list)
    for config in (inrange.test_scenario(i) for i in range(len(inrange))):
        families = _families(config)
        assert len(families) == 1, (config.name, families)
        for family, (lo, hi) in families.items():
            low, high = ranges[config.ship.model][family]
            factor = CURRENT_FACTOR if family == "current" else (1.0, 1.0)
            assert low * factor[0] - 1e-9 <= lo and hi <= high * factor[1] + 1e-9
            seen[config.ship.model].append(family)
    assert sorted(set(seen["nomoto2"])) == ["aging", "d0_shift", "gain"]
    for ship in SHIPS[1:]:
        assert sorted(seen[ship]) == ["aging", "current", "gain", "loading"], ship


def test_inrange_seeds_are_apart_from_validation_heldout_and_training() -> None:
    """The in-range split's seed space: SeedSequence([TEST_SALT, crc32("inrange"), j],
    spawn_key=(k,)), its own name key (apart from the validation and held-out splits'), the
    test salt (apart from training's [TRAIN_SALT, s]); no in-range trial equals a
    validation, held-out or catalogue one."""
    import zlib

    from shipgym.scenarios.sampling import TEST_SALT, TRAIN_SALT, test_rng

    keys = {name: zlib.crc32(name.encode()) for name in ("inrange", "validation", "heldout")}
    assert keys["inrange"] == 0xE4191536 and len(set(keys.values())) == 3
    assert TEST_SALT != TRAIN_SALT
    for j in range(4):
        for k in range(4):
            ours = test_rng("inrange", j, k).bit_generator.seed_seq
            assert ours.entropy == [TEST_SALT, keys["inrange"], j]
            assert ours.spawn_key == ((k,) if k else ())
    assert train_rng(7).bit_generator.seed_seq.entropy == [TRAIN_SALT, 7]
    inrange, validation = load_distribution("inrange"), load_distribution("validation")
    heldout = load_distribution("heldout")
    ours = {_content(inrange.test_scenario(i)) for i in range(len(inrange))}
    theirs = {_content(validation.test_scenario(i)) for i in range(len(validation))}
    theirs |= {_content(heldout.test_scenario(i)) for i in range(len(heldout))}
    theirs |= {_content(load_scenario(name).config) for name in list_scenarios()}
    assert len(ours) == 16 and not ours & theirs


def test_the_leaderboards_splits_are_test_only_and_a_train_split_cannot_be() -> None:
    """``test_only`` marks the splits tuning and model selection refuse (the held-out and
    in-range ones); a train split with it is refused, naming the key."""
    assert load_distribution("heldout").config.test_only
    assert load_distribution("inrange").config.test_only
    assert not load_distribution("validation").config.test_only
    data = {**_raw("train"), "test_only": True}
    with pytest.raises(ValueError, match="test_only: only a test split"):
        DistributionConfig.model_validate(data)


@pytest.mark.parametrize("name", ["train", "heldout"])
def test_an_unseen_hull_is_refused_by_a_distribution_that_is_not_test_only(
    name: str, tmp_path: Path
) -> None:
    """The KVLCC2 (UNSEEN_HULLS) may be listed only by a test_only distribution: a copy of
    the training file, or of the held-out one without ``test_only``, that lists it is
    refused, naming the key (the validation split reads its ships from the training one)."""
    data = _raw(name)
    data.pop("test_only", None)
    share = {"weight": 1.0} if name == "train" else {"count": 1}
    data["ships"].append({"model": "kvlcc2", **share})
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    key = f"ships.{len(data['ships']) - 1}.model"
    with pytest.raises(DistributionError, match=rf"{re.escape(key)}: kvlcc2 is an unseen hull"):
        load_distribution(bad)


def test_training_and_validation_never_build_the_unseen_hull(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A spy on the KVLCC2 model's construction: 400 training draws and the 32 validation
    trials never build it (while a kvlcc2 catalogue scenario does)."""
    from shipgym.models.kvlcc2 import KVLCC2

    built: list[str] = []
    real = KVLCC2.from_config.__func__  # type: ignore[attr-defined]

    def spy(cls: type, *args: Any, **kwargs: Any) -> Any:
        built.append(cls.__name__)
        return real(cls, *args, **kwargs)

    monkeypatch.setattr(KVLCC2, "from_config", classmethod(spy))
    _train_draws(400)
    validation = load_distribution("validation")
    for index in range(32):
        validation.test_scenario(index)
    assert built == []
    load_scenario("kvlcc2_nominal")
    assert built  # the spy sees a construction
