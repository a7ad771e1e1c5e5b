"""The leaderboard's trials, training seeds, row intervals and ranking (docs/leaderboard.md)."""

from __future__ import annotations

import io
import json
import shutil
import sys
from pathlib import Path

import pytest

from shipgym.config import ConfigError
from shipgym_baselines.errors import RunError
from shipgym_baselines.leaderboard.jobs import Job, plan_jobs, plan_run, run_batch, run_job
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.learned.policy import model_zip
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.runrecord import read_run
from shipgym_baselines.scoring.tables import COLUMNS
from tests.baselines.records.conftest import TIMING, untimed, write_suite

RANDOMIZE = {
    "cross_track_offset_L": [-1.0, 1.0],
    "heading_error_deg": [-10.0, 10.0],
    "jump_time_jitter_s": [-5.0, 5.0],
}
#: aggregate.json's fields, exactly
AGGREGATE_KEYS = {
    "controller",
    "kind",
    "split",
    "scenarios",
    "runs",
    "training_seeds",
    "cost_ratio_iqm",
    "cost_ratio_iqm_ci95",
    "cost_ratio_gmean",
    "cost_ratio_gmean_ci95",
    "prob_improvement_over_pid_los",
    "prob_improvement_over_pid_los_ci95",
    "failure_rate",
    "failure_rate_ci95",
    "cost_vs_frozen_gmean",
    "cost_vs_frozen_gmean_ci95",
    "prob_beats_frozen",
    "prob_beats_frozen_ci95",
    "gap_closed_iqm",
    "gap_closed_iqm_ci95",
    "gap_trials",
    "nominal_cost_ratio_gmean",
    "nominal_cost_ratio_gmean_ci95",
    "change_share_iqm",
    "change_share_iqm_ci95",
    "change_trials",
    "share_trials",
}
#: the stand-in oracle's cost: this fraction of pid_los's on the same trial
STAND_IN = 0.8


def run(suite: str, out: Path, **kwargs: object) -> list[dict]:
    return run_leaderboard(suite, out_dir=out, workers=1, show_progress=False, **kwargs)


def with_stand_in_oracle(run_folder: Path, out: Path) -> Path:
    """A copy of a run record (``run.json``, ``episodes.jsonl``) with a stand-in ``oracle``
    (kind reference, a player of the no-change twins as in a run with the oracle): each
    pid_los episode again, its cost × :data:`STAND_IN`; then the report of it in
    ``out / "report"``, whose folder is returned."""
    from shipgym_baselines.leaderboard.report import write_report

    record = json.loads((run_folder / "run.json").read_text())
    entry = {"name": "oracle", "controller": "oracle", "kind": "reference"}
    record["suite"]["controllers"].append({**entry, "training_seeds": [None]})
    if "twin_players" in record["suite"]:
        record["suite"]["twin_players"].append("oracle")
    copy = out / "record"
    copy.mkdir(parents=True)
    (copy / "run.json").write_text(json.dumps(record))
    lines = []
    for line in (run_folder / "episodes.jsonl").read_text().splitlines():
        lines.append(line)
        episode = json.loads(line)  # strict JSON: "inf" stays a string
        if episode["controller"] == "pid_los":
            oracle = {**episode, "controller": "oracle", "kind": "reference"}
            lines.append(json.dumps({**oracle, "cost": STAND_IN * episode["cost"]}))
    (copy / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    write_report([copy], out / "report")
    return out / "report"


@pytest.fixture(scope="module")
def ranked(randomised: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The randomised run reported with a stand-in oracle."""
    return with_stand_in_oracle(randomised, tmp_path_factory.mktemp("ranked"))


def untimed_episodes(folder: Path) -> list[dict]:
    return [{k: v for k, v in e.items() if not k.startswith(TIMING)} for e in read_episodes(folder)]


@pytest.fixture(scope="module")
def randomised(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """pid_los and zero_rudder on two nomoto2 scenarios, 3 randomised trials each."""
    root = tmp_path_factory.mktemp("randomised")
    run(write_suite(root, seeds=3, randomize=RANDOMIZE), root / "out")
    return root / "out"


@pytest.fixture(scope="module")
def agent(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A trained agent's folder with two training seeds (``seed_0``, ``seed_1``: copies of
    the shipped ppo's first, the meta's seed set to the folder's)."""
    folder = tmp_path_factory.mktemp("agents") / "agent"
    for k in (0, 1):
        shutil.copytree(model_zip("ppo").parent, folder / f"seed_{k}")
        meta = folder / f"seed_{k}" / "meta.json"
        meta.write_text(json.dumps({**json.loads(meta.read_text()), "seed": k}))
    return folder


def test_rows_carry_an_interval_for_every_metric(randomised: Path) -> None:
    rows = json.loads((randomised / "leaderboard.json").read_text())
    episodes = read_episodes(randomised)
    assert len(rows) == 4
    for row in rows:
        assert row["seeds"] == row["episodes"] == 3
        assert row["training_seeds"] == 0 and row["training_seed_list"] == []
        mine = [
            e
            for e in episodes
            if (e["scenario"], e["controller"]) == (row["scenario"], row["controller"])
        ]
        for metric in COLUMNS:
            assert f"{metric}_std" in row and f"{metric}_ci95" in row
        for metric in ("ace", "return", "rudder_travel", "J", "mean_abs_cross_track"):
            low, high = row[f"{metric}_ci95"]
            values = [float(e[metric]) for e in mine]
            eps = 1e-12 * max(1.0, max(abs(v) for v in values))  # a resample mean's last bit
            assert min(values) - eps <= low <= row[metric] <= high <= max(values) + eps, (
                row,
                metric,
            )
        for metric in ("ace", "return"):  # three different trials: a spread
            assert row[f"{metric}_ci95"][0] < row[metric] < row[f"{metric}_ci95"][1]
        low, high = row["success_ci95"]
        assert 0.0 <= low <= row["success"] <= high <= 1.0
    pair = ("zero_rudder", "rudder_aging")
    (never,) = [r for r in rows if (r["controller"], r["scenario"]) == pair]
    assert never["t_c"] is None and never["t_c_ci95"] is None  # never converged


def test_without_the_oracle_the_ranking_says_what_it_needs(randomised: Path) -> None:
    from shipgym_baselines.leaderboard.outputs import terminal_summary

    assert json.loads((randomised / "aggregate.json").read_text()) == []
    assert json.loads((randomised / "scenario_scores.json").read_text()) == []
    for text in ((randomised / "leaderboard.md").read_text(), terminal_summary(randomised)):
        assert "No ranking: the cost ratio needs the episodes of the reference `oracle`" in text
    assert terminal_summary(randomised).endswith(f"leaderboard: {randomised}/leaderboard.html")


def test_aggregate_json_ranks_by_cost_over_the_oracle(randomised: Path, ranked: Path) -> None:
    board = json.loads((ranked / "aggregate.json").read_text())
    assert [(r["split"], r["controller"]) for r in board] == [("catalogue", "pid_los")]
    (pid,) = board  # zero_rudder and the oracle are references: not ranked
    assert set(pid) == AGGREGATE_KEYS
    assert pid["scenarios"] == ["nominal", "rudder_aging"] and pid["kind"] == "classical"
    assert pid["runs"] == 3 and pid["training_seeds"] == 0
    for key in ("cost_ratio_iqm", "cost_ratio_gmean"):
        assert pid[key] == pytest.approx(1 / STAND_IN)
        assert pid[f"{key}_ci95"] == pytest.approx([1 / STAND_IN] * 2)
    assert pid["prob_improvement_over_pid_los"] is None  # no comparison with itself
    assert pid["failure_rate"] == 0.0 and pid["failure_rate_ci95"] == [0.0, 0.0]
    # rudder_aging's no-change twin is nominal (the same trials without the change): the
    # nominal ratio is pid_los's cost over the oracle's there, on rudder_aging's 3 trials
    assert read_run(randomised)["suite"]["twins"] == {"rudder_aging": "nominal"}
    assert pid["nominal_cost_ratio_gmean"] == pytest.approx(1 / STAND_IN)
    assert pid["nominal_cost_ratio_gmean_ci95"] == pytest.approx([1 / STAND_IN] * 2)
    assert pid["change_trials"] == 3
    # no frozen optimum: no trial to take a change share over
    assert pid["change_share_iqm"] is None and pid["share_trials"] == 0
    episodes = read_episodes(randomised)
    scores = {s["scenario"]: s for s in json.loads((ranked / "scenario_scores.json").read_text())}
    assert sorted(scores) == ["nominal", "rudder_aging"]
    for scenario, entry in scores.items():
        pid_costs = [
            e["cost"] for e in episodes if (e["controller"], e["scenario"]) == ("pid_los", scenario)
        ]
        assert entry["oracle_cost"] == pytest.approx(STAND_IN * sum(pid_costs) / 3)
        cells = {c["controller"]: c for c in entry["controllers"]}
        assert cells["pid_los"]["cost_ratio_gmean"] == pytest.approx(1 / STAND_IN)
        assert cells["zero_rudder"]["cost_ratio_gmean"] > 2.0  # doing nothing costs
    for name in ("ranking_catalogue.png", "profile_catalogue.png"):
        assert (ranked / name).is_file(), name
    assert not list(ranked.glob("*.svg*"))  # vector copies only with --vector-figures


def test_the_same_episodes_give_the_same_aggregate_json_bit_for_bit(
    randomised: Path, ranked: Path, tmp_path: Path
) -> None:
    again = with_stand_in_oracle(randomised, tmp_path)
    for name in ("aggregate.json", "scenario_scores.json"):
        assert (again / name).read_bytes() == (ranked / name).read_bytes(), name


def test_the_markdown_opens_with_the_ranking(ranked: Path) -> None:
    text = (ranked / "leaderboard.md").read_text()
    assert text.startswith("# Leaderboard\n\n`pid_los` is the only ranked controller")  # verdict
    assert "\n\n## Ranking\n\nAn episode's cost is the sum" in text
    ranking, rest = text.split("## Cost ratio per scenario", 1)
    assert "### Catalogue scenarios (2, the same for every controller)" in ranking
    assert "| rank | controller | kind | training seeds | scenarios | cost ratio IQM" in ranking
    first = next(line for line in ranking.splitlines() if line.startswith("| 1 |"))
    assert first.startswith("| 1 | pid_los | classical | – | 2 | 1.250 [1.250, 1.250] |")
    assert "Resolution, catalogue: median width of the cost-ratio IQM intervals 0.000" in ranking
    scores, rows = rest.split("## All rows", 1)
    assert "| controller | nominal | rudder_aging |" in scores
    assert "| pid_los | 1.250 [1.250, 1.250] | 1.250 [1.250, 1.250] |" in scores
    assert "| oracle (cost) |" in scores
    assert "| rudder_aging | zero_rudder | reference | 3 |" in rows


def test_the_markdown_the_terminal_and_the_page_open_with_the_verdict(
    randomised: Path, ranked: Path
) -> None:
    """The run's sentences (shipgym_baselines.page.verdict; two without the frozen
    optimum) first; a report folder (no episodes of its own) prints those its leaderboard.md
    opens with; no ranking: none."""
    from shipgym_baselines.leaderboard.outputs import terminal_summary

    verdict = (
        "`pid_los` is the only ranked controller on the 2 catalogue scenarios, at IQM 1.250 "
        "[1.250, 1.250]. No learned agent is ranked; the failure rate is 0 %."
    )
    assert (ranked / "leaderboard.md").read_text().startswith(f"# Leaderboard\n\n{verdict}\n\n")
    assert terminal_summary(ranked).startswith(f"{verdict}\n\n## Ranking")
    html = (ranked / "leaderboard.html").read_text()
    plain = verdict.replace("`", "").replace("'", "&#x27;")
    assert f'<p id="verdict">{plain}</p><h2 id="ranking">' in html
    assert html.index('id="verdict"') < html.index("<table")
    assert (
        "leads" not in terminal_summary(randomised)
        and 'id="verdict"' not in (randomised / "leaderboard.html").read_text()
    )
    assert "only ranked" not in (randomised / "leaderboard.md").read_text()


def test_trials_are_reproducible_per_seed_and_differ_across_seeds(
    randomised: Path, tmp_path: Path
) -> None:
    run(write_suite(tmp_path, seeds=3, randomize=RANDOMIZE), tmp_path / "again")
    assert untimed_episodes(tmp_path / "again") == untimed_episodes(randomised)
    pid = [e for e in read_episodes(randomised) if e["controller"] == "pid_los"]
    assert len({e["ace"] for e in pid}) == len(pid) == 6  # every trial its own episode
    starts = {}
    for seed in (10_000, 10_001, 10_002, 10_000):
        result = run_job(("pid_los", "nominal", seed, None, RANDOMIZE))
        start = (result.trajectory["x"][0], result.trajectory["y"][0])
        assert starts.setdefault(seed, start) == start  # the same seed: the same start
    assert len(set(starts.values())) == 3
    # without randomisation every seed of the deterministic scenario is the same episode
    fixed = [run_job(("pid_los", "nominal", seed)) for seed in (10_000, 10_001)]
    assert fixed[0].metrics["ace"] == fixed[1].metrics["ace"]
    assert (fixed[0].trajectory["x"][0], fixed[0].trajectory["y"][0]) == (0.0, 0.0)


def test_run_json_keeps_the_randomisation_and_resume_refuses_another(
    randomised: Path, tmp_path: Path
) -> None:
    suite = read_run(randomised)["suite"]
    assert suite["randomize"] == {
        **RANDOMIZE,
        "current_speed_factor": None,
        "current_direction_deg": None,
    }
    assert [c["training_seeds"] for c in suite["controllers"]] == [[None], [None]]
    other = write_suite(tmp_path, seeds=3, randomize={**RANDOMIZE, "heading_error_deg": [0, 5]})
    with pytest.raises(RunError, match=r"suite differs.*randomize\.heading_error_deg"):
        run(other, randomised, resume=True)
    with pytest.raises(RunError, match=r"randomize: \{.* in the run, null now"):
        run(write_suite(tmp_path, seeds=3), randomised, resume=True)


def test_a_learned_job_is_one_training_seed_on_all_seeds(agent: Path) -> None:
    seeds_of = {"agent": [0, 1], "pid_los": [None]}
    jobs = plan_jobs([str(agent), "pid_los"], ["nominal"], [7, 8], seeds_of, None, set())
    assert [(j.seeds, j.training_seed) for j in jobs] == [
        ((7, 8), 0),
        ((7, 8), 1),
        ((7, 8), None),  # a classical controller's seeds in lockstep too
    ]
    oracle = plan_jobs(["oracle"], ["nominal"], [7, 8], {"oracle": [None]}, None, set())
    assert [j.seeds for j in oracle] == [(7,), (8,)]  # the reference table, trial by trial
    # batched through evaluate_batch: the episodes run_job gives one by one, trial by trial
    batch = run_batch(Job(str(agent), "rudder_aging", (10_000, 10_001), 1, RANDOMIZE))
    for result in batch:
        alone = run_job((str(agent), "rudder_aging", result.seed, 1, RANDOMIZE))
        assert result.training_seed == alone.training_seed == 1
        assert untimed([result.row()]) == untimed([alone.row()])


@pytest.fixture(scope="module")
def with_agent(tmp_path_factory: pytest.TempPathFactory, agent: Path) -> tuple[str, Path]:
    """(suite, clean run) of the agent with its two training seeds beside the references."""
    root = tmp_path_factory.mktemp("with_agent")
    suite = write_suite(
        root,
        scenarios=["rudder_aging"],
        controllers=[str(agent), "pid_los", "zero_rudder"],
        seeds=2,
        randomize=RANDOMIZE,
    )
    run(suite, root / "clean")
    return suite, root / "clean"


def test_a_learned_row_aggregates_training_seeds_times_evaluation_seeds(
    with_agent: tuple[str, Path], tmp_path: Path
) -> None:
    _, clean = with_agent
    twin = read_run(clean)["suite"]["twins"]["rudder_aging"]
    assert twin == "twin:rudder_aging"  # no scenario of the run is rudder_aging's twin
    learned = [e for e in read_episodes(clean) if e["controller"] == "agent"]
    runs = [(0, 10_000), (0, 10_001), (1, 10_000), (1, 10_001)]
    for scenario in ("rudder_aging", twin):  # the agent plays the twin as its scenario
        mine = [e for e in learned if e["scenario"] == scenario]
        assert sorted((e["training_seed"], e["seed"]) for e in mine) == runs
    assert len(learned) == 2 * len(runs)
    rows = json.loads((clean / "leaderboard.json").read_text())
    (row,) = [r for r in rows if r["kind"] == "learned"]
    assert (row["seeds"], row["training_seeds"], row["training_seed_list"]) == (2, 2, [0, 1])
    assert row["episodes"] == 4 and len(row["ace_ci95"]) == len(row["return_ci95"]) == 2
    ranked = with_stand_in_oracle(clean, tmp_path)
    board = {r["controller"]: r for r in json.loads((ranked / "aggregate.json").read_text())}
    assert (board["agent"]["training_seeds"], board["agent"]["runs"]) == (2, 4)
    controllers = read_run(clean)["suite"]["controllers"]
    assert [c["training_seeds"] for c in controllers] == [[0, 1], [None], [None]]
    # one kept trajectory per row: the episode its figure draws (none of the twin's rows)
    assert len(list((clean / "trajectories").iterdir())) == 3


def test_shared_trials_give_each_seed_to_one_training_seed(agent: Path, tmp_path: Path) -> None:
    """``learned_trials: shared``: the agent's two training seeds share three evaluation
    seeds, each played once as :func:`dealt_seeds` deals them by the name of the scenario's
    no-change twin (so each trial and its twin go to one training seed); its row has three
    episodes and three runs, like a classical controller's; ``run.json`` records the deal,
    an episode of the other training seed is refused, and a run of the other deal is not
    reported with it."""
    from shipgym_baselines.leaderboard.report import merge_runs
    from shipgym_baselines.records.trials import deal_names, dealt_seeds

    suite = write_suite(
        tmp_path,
        scenarios=["rudder_aging"],
        controllers=[str(agent), "pid_los"],
        seeds=3,
        randomize=RANDOMIZE,
        learned_trials="shared",
    )
    out = tmp_path / "out"
    run(suite, out)
    record = read_run(out)["suite"]
    assert record["learned_trials"] == "shared"
    twin = deal_names(record)["rudder_aging"]  # the name rudder_aging's trials are dealt by
    assert twin == record["twins"]["rudder_aging"] == "twin:rudder_aging"
    learned = [e for e in read_episodes(out) if e["controller"] == "agent"]
    seeds = [10_000, 10_001, 10_002]
    dealt = dealt_seeds(twin, seeds, [0, 1])
    expected = sorted((k, s) for k, mine in dealt.items() for s in mine)
    for scenario in ("rudder_aging", twin):  # a trial and its twin: one training seed
        mine = [e for e in learned if e["scenario"] == scenario]
        assert sorted((e["training_seed"], e["seed"]) for e in mine) == expected
        assert sorted(e["seed"] for e in mine) == seeds
    # one lockstep job for both training seeds on each: each episode as its training seed alone
    seeds_of = {"agent": [0, 1], "pid_los": [None]}
    jobs = {j.scenario: j for j in plan_run([str(agent), "pid_los"], record, seeds_of) if j.dealt}
    assert sorted(jobs) == ["rudder_aging", twin]
    job = jobs["rudder_aging"]
    assert job.training_seed is None
    assert sorted(job.runs()) == sorted(jobs[twin].runs()) == sorted((s, k) for k, s in expected)
    for result in run_batch(job):
        alone = run_job((str(agent), "rudder_aging", result.seed, result.training_seed, RANDOMIZE))
        assert untimed([result.row()]) == untimed([alone.row()])
    rows = json.loads((out / "leaderboard.json").read_text())
    (row,) = [r for r in rows if r["kind"] == "learned"]
    assert (row["seeds"], row["training_seeds"], row["episodes"]) == (3, 2, 3)
    assert "| 3 shared by 2 trained |" in (out / "leaderboard.md").read_text()
    ranked = with_stand_in_oracle(out, tmp_path)
    board = {r["controller"]: r for r in json.loads((ranked / "aggregate.json").read_text())}
    assert (board["agent"]["training_seeds"], board["agent"]["runs"]) == (2, 3)
    assert board["agent"]["runs"] == board["pid_los"]["runs"]
    # cut short inside the agent's job, then resumed: the same rows as the clean run
    cut = tmp_path / "cut"

    def stop_after_two(result: object, seen: list[int] = []) -> None:  # noqa: B006
        seen.append(1)
        if len(seen) == 2:  # inside the agent's job: its third episode is left to resume
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run(suite, cut, on_episode=stop_after_two)
    ran: list = []
    resumed = run(suite, cut, resume=True, on_episode=ran.append)
    assert "agent" in {r.controller for r in ran}
    # rudder_aging and its twin × 3 seeds × the agent and pid_los
    assert len(read_episodes(cut)) == len(read_episodes(out)) == 2 * 3 * 2
    assert untimed(resumed) == untimed(json.loads((out / "leaderboard.json").read_text()))
    # an episode of the training seed the seed was not dealt to
    other = tmp_path / "other"
    shutil.copytree(out, other)
    first = learned[0]
    with open(other / "episodes.jsonl", "a") as fh:
        fh.write(json.dumps({**first, "training_seed": 1 - first["training_seed"]}) + "\n")
    with pytest.raises(RunError, match="dealt to another training seed"):
        read_episodes(other, suite=read_run(other)["suite"])
    every = tmp_path / "every"
    alone = write_suite(
        tmp_path, scenarios=["rudder_aging"], controllers=["pid_los"], randomize=RANDOMIZE
    )
    run(alone, every)
    with pytest.raises(RunError, match="deal learned agents' trials differently"):
        merge_runs([out, every])


def test_resume_with_training_seeds_equals_a_clean_run(
    with_agent: tuple[str, Path], tmp_path: Path
) -> None:
    """Cut short, then resumed with 2 workers: the same rows, and (with the stand-in oracle)
    the same aggregate.json and scenario_scores.json, bit for bit."""
    suite, clean = with_agent
    out = tmp_path / "out"

    def stop_after_three(result: object, seen: list[int] = []) -> None:  # noqa: B006
        seen.append(1)
        if len(seen) == 3:  # inside the agent's second training seed's job
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run(suite, out, on_episode=stop_after_three)
    assert len(read_episodes(out)) == 3
    ran: list[object] = []
    rows = run_leaderboard(
        suite, out_dir=out, workers=2, show_progress=False, resume=True, on_episode=ran.append
    )
    assert ("agent", 1) in [(r.controller, r.training_seed) for r in ran]
    # 2 seeds: the agent's 2 training seeds, pid_los and zero_rudder on rudder_aging, the
    # agent's and pid_los's on its twin (zero_rudder, a reference, plays no twin)
    total = 2 * (2 + 1 + 1) + 2 * (2 + 1)
    assert len(read_episodes(clean)) == total
    assert len(ran) == total - 3 and len(read_episodes(out)) == total
    board = json.loads((clean / "leaderboard.json").read_text())
    assert untimed(rows) == untimed(board)
    for name in ("aggregate.json", "scenario_scores.json"):
        assert (out / name).read_text() == (clean / name).read_text(), name
    resumed = with_stand_in_oracle(out, tmp_path / "resumed")
    reference = with_stand_in_oracle(clean, tmp_path / "clean")
    ranked = json.loads((resumed / "aggregate.json").read_text())
    assert sorted(r["controller"] for r in ranked) == ["agent", "pid_los"]
    for name in ("aggregate.json", "scenario_scores.json"):
        assert (resumed / name).read_bytes() == (reference / name).read_bytes(), name
    assert sorted(p.name for p in (out / "trajectories").iterdir()) == sorted(
        p.name for p in (clean / "trajectories").iterdir()
    )


def test_the_terminal_ends_with_the_ranking_and_the_page(
    ranked: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``report`` (like ``leaderboard``) prints the ranking and where the page is, not the
    long rows."""
    from shipgym_baselines.cli import main

    out = tmp_path / "again"
    assert main(["report", str(ranked.parent / "record"), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert text.rstrip().endswith(f"leaderboard: {out / 'leaderboard.html'}")
    assert "| 1 | pid_los | classical |" in text and "Resolution, catalogue" in text
    assert "| scenario | controller |" not in text


@pytest.mark.parametrize("workers", [1, 2])
def test_finding3_a_scenario_edited_mid_run_has_no_effect(tmp_path: Path, workers: int) -> None:
    """The scenario file is rewritten (a 20 s time limit instead of 90 s, another start)
    once the first episode is recorded: every episode still runs the scenario as run.json
    recorded it at the start, in the parent and in the pool's workers."""
    case = tmp_path / "case.yaml"
    nominal = (Path(__file__).resolve().parents[3] / "configs/scenarios/nominal.yaml").read_text()
    original = nominal.replace("name: nominal", "name: case")
    case.write_text(original)
    suite = write_suite(tmp_path, scenarios=[str(case)], seeds=4)

    def edit_once(result: object, seen: list[object] = []) -> None:  # noqa: B006
        seen.append(result)
        if len(seen) == 1:
            edited = original.replace("time_limit: 90.0", "time_limit: 20.0")
            case.write_text(edited.replace("heading_deg: 0.0", "heading_deg: 40.0"))

    out = tmp_path / "out"
    run_leaderboard(suite, out_dir=out, workers=workers, show_progress=False, on_episode=edit_once)
    assert "time_limit: 20.0" in case.read_text()
    record = read_run(out)
    assert record["suite"]["scenario_files"] == {"case": str(case)}
    settings = record["suite"]["scenarios"]["case"]
    assert settings["time_limit"] == 90.0 and settings["initial_state"]["heading_deg"] == 0.0
    assert record["status"] == "complete"
    for controller in ("pid_los", "zero_rudder"):
        episodes = [e for e in untimed_episodes(out) if e["controller"] == controller]
        assert len(episodes) == 4
        # no randomisation: every seed's episode is the recorded scenario's, step for step
        assert len({(e["steps"], e["ace"], e["duration"]) for e in episodes}) == 1
    # the edit matters: the file as it is now gives other episodes
    recorded = {e["controller"]: e for e in untimed_episodes(out)}
    for controller in ("pid_los", "zero_rudder"):
        now = run_job((controller, str(case), 10_000)).metrics
        assert (now["steps"], now["ace"]) != (
            recorded[controller]["steps"],
            recorded[controller]["ace"],
        )


@pytest.mark.slow
def test_quick_suite_finishes(tmp_path: Path) -> None:
    """The quick suite runs to the end with every controller on its 12
    scenarios (one evaluation seed here, to keep CI short; the suite's own is 3): a row per
    controller and scenario, every applicable one with its episodes."""
    from shipgym_baselines.suite import load_suite

    quick = load_suite("quick")
    rows = run_leaderboard("quick", seeds=1, out_dir=tmp_path, workers=2, show_progress=False)
    assert {r["scenario"] for r in rows} == set(quick.scenarios)
    assert len(rows) == len(quick.scenarios) * len(quick.controllers)
    applies = [r for r in rows if r["applies"]]
    assert all(r["episodes"] == r["seeds"] * max(1, r["training_seeds"]) for r in applies)
    assert {r["controller"] for r in applies if r["scenario"] == "blanke_rudder_aging"} >= {
        "pid_los",
        "l1_backstepping",
        "ppo",
    }
    assert read_run(tmp_path)["status"] == "complete"


# --- the suite's own scenarios ---------------------------------------------------------------

NOMINAL = Path(__file__).resolve().parents[3] / "configs/scenarios/nominal.yaml"


def own_scenario(folder: Path, file: str, name: str, time_limit: float = 40.0) -> Path:
    """The catalogue's ``nominal`` as a file of its own: ``name``, a shorter time limit."""
    text = NOMINAL.read_text().replace("name: nominal", f"name: {name}")
    path = folder / file
    path.write_text(text.replace("time_limit: 90.0", f"time_limit: {time_limit}"))
    return path


@pytest.fixture(scope="module")
def own_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, str]:
    """pid_los and zero_rudder on ``rudder_aging`` and a scenario file named ``my_turn``:
    (the run's folder, the scenario file, the suite file)."""
    root = tmp_path_factory.mktemp("own")
    file = own_scenario(root, "turn_v2.yaml", "my_turn")
    suite = write_suite(root, scenarios=["rudder_aging", "turn_v2.yaml"], seeds=2)
    run(suite, root / "out")
    return root / "out", file, suite


def test_a_scenario_file_is_named_by_its_name_in_the_record_and_rows(
    own_run: tuple[Path, Path, str],
) -> None:
    out, file, _ = own_run
    suite = read_run(out)["suite"]
    assert list(suite["scenarios"]) == ["rudder_aging", "my_turn"]
    assert suite["scenario_files"] == {"my_turn": str(file)}  # where its content came from
    assert suite["scenarios"]["my_turn"]["time_limit"] == 40.0
    # rudder_aging's no-change twin is no scenario of the run (my_turn stops at 40 s)
    assert suite["twins"] == {"rudder_aging": "twin:rudder_aging"}
    assert list(suite["twin_scenarios"]) == ["twin:rudder_aging"]
    assert {e["scenario"] for e in read_episodes(out)} == {
        "rudder_aging",
        "my_turn",
        "twin:rudder_aging",
    }
    rows = json.loads((out / "leaderboard.json").read_text())
    assert {(r["scenario"], r["split"]) for r in rows} == {
        ("rudder_aging", "catalogue"),
        ("my_turn", "yours"),
    }
    assert "| my_turn | pid_los |" in (out / "leaderboard.md").read_text()
    assert str(file) not in (out / "leaderboard.md").read_text()
    assert (out / "scenario_my_turn.png").is_file()


def test_your_scenarios_are_ranked_in_a_group_of_their_own(
    own_run: tuple[Path, Path, str], tmp_path: Path
) -> None:
    out, _, _ = own_run
    ranked = with_stand_in_oracle(out, tmp_path)  # the report keeps the files' names
    board = json.loads((ranked / "aggregate.json").read_text())
    assert [(r["split"], r["controller"], r["scenarios"]) for r in board] == [
        ("catalogue", "pid_los", ["rudder_aging"]),
        ("yours", "pid_los", ["my_turn"]),
    ]
    # the report keeps the twin too: rudder_aging's nominal ratio, none on my_turn (no change)
    catalogue, yours = board
    assert catalogue["nominal_cost_ratio_gmean"] == pytest.approx(1 / STAND_IN)
    assert catalogue["change_trials"] == 2
    assert yours["nominal_cost_ratio_gmean"] is None and yours["change_trials"] is None
    scores = json.loads((ranked / "scenario_scores.json").read_text())
    assert {(s["scenario"], s["split"]) for s in scores} == {
        ("rudder_aging", "catalogue"),
        ("my_turn", "yours"),
    }
    text = (ranked / "leaderboard.md").read_text()
    assert "### Catalogue scenarios (1, the same for every controller)" in text
    assert "### Your scenarios (1, the same for every controller)" in text
    assert "| controller | rudder_aging | my_turn |" in text
    assert (ranked / "ranking_yours.png").is_file()
    assert "Your scenarios" in (ranked / "leaderboard.html").read_text()


def test_a_run_with_your_scenario_resumes_and_replays(
    own_run: tuple[Path, Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--resume`` finds the same suite (names and the file's content); ``shipgym run
    NAME --suite SUITE`` replays the leaderboard's episode of the file named NAME."""
    from shipgym_baselines.cli import main

    out, _, suite = own_run
    before = read_episodes(out)
    run(suite, out, resume=True)  # nothing missing: nothing runs, nothing refused
    assert read_episodes(out) == before
    replay = tmp_path / "replay"
    args = ["run", "my_turn", "pid_los", "--suite", suite, "--seed", "10001", "--out", str(replay)]
    assert main([*args, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    (recorded,) = [
        e
        for e in before
        if (e["scenario"], e["controller"], e["seed"]) == ("my_turn", "pid_los", 10001)
    ]
    assert doc["scenario"] == "my_turn"
    assert (doc["ace"], doc["cost"], doc["steps"]) == (
        recorded["ace"],
        recorded["cost"],
        recorded["steps"],
    )


def test_a_scenario_file_named_as_another_is_refused_naming_both(tmp_path: Path) -> None:
    first = own_scenario(tmp_path, "a.yaml", "my_turn")
    second = own_scenario(tmp_path, "b.yaml", "my_turn", time_limit=30.0)
    suite = write_suite(tmp_path, scenarios=["nominal", "a.yaml", "b.yaml"])
    with pytest.raises(ConfigError) as info:
        run(suite, tmp_path / "out")
    message = str(info.value)
    assert f"scenario files {first} and {second} are both named 'my_turn'" in message
    assert not (tmp_path / "out").exists()


def test_a_scenario_file_named_as_a_catalogue_scenario_is_refused(tmp_path: Path) -> None:
    file = own_scenario(tmp_path, "mine.yaml", "rudder_aging")
    suite = write_suite(tmp_path, scenarios=["mine.yaml"])
    with pytest.raises(ConfigError) as info:
        run(suite, tmp_path / "out")
    assert (
        f"scenario file {file} is named 'rudder_aging', as the catalogue's scenario "
        "configs/scenarios/rudder_aging.yaml, but its settings differ"
    ) in str(info.value)


def test_a_copy_of_a_catalogue_scenario_is_that_scenario(tmp_path: Path) -> None:
    from shipgym_baselines.leaderboard.jobs import suite_record, suite_scenarios
    from shipgym_baselines.suite import load_suite

    copy = tmp_path / "copy.yaml"
    copy.write_text(NOMINAL.read_text())
    spec = load_suite(write_suite(tmp_path, scenarios=["copy.yaml", "rudder_aging"]))
    scenarios = suite_scenarios(spec.all_scenarios())
    assert list(scenarios) == ["nominal", "rudder_aging"]
    record = suite_record(spec, ["pid_los"], scenarios, [10_000], {"pid_los": [None]})
    assert "scenario_files" not in record  # grouped with the catalogue


#: the stand-in frozen optimum's cost: this factor times pid_los's on the same trial (so the
#: headroom is FROZEN / STAND_IN = 2.5 on every trial)
FROZEN = 2.0


def with_stand_in_references(run_folder: Path, out: Path) -> Path:
    """:func:`with_stand_in_oracle`'s record with a stand-in ``oracle_frozen`` too (kind
    reference): each pid_los episode again, its cost × :data:`FROZEN`, except on a twin that
    is no scenario of the run (the frozen optimum plays no twin); the report of it in
    ``out / "gap"``, whose folder is returned."""
    from shipgym_baselines.leaderboard.report import write_report

    with_stand_in_oracle(run_folder, out)
    record = out / "record"
    run_json = json.loads((record / "run.json").read_text())
    entry = {"name": "oracle_frozen", "controller": "oracle_frozen", "kind": "reference"}
    run_json["suite"]["controllers"].append({**entry, "training_seeds": [None]})
    (record / "run.json").write_text(json.dumps(run_json))
    lines = (record / "episodes.jsonl").read_text().splitlines()
    twins = run_json["suite"].get("twin_scenarios", {})
    for line in list(lines):
        episode = json.loads(line)
        if episode["controller"] == "pid_los" and episode["scenario"] not in twins:
            frozen = {**episode, "controller": "oracle_frozen", "kind": "reference"}
            lines.append(json.dumps({**frozen, "cost": FROZEN * episode["cost"]}))
    (record / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    write_report([record], out / "gap")
    return out / "gap"


def test_the_gap_to_the_frozen_optimum_in_every_output(randomised: Path, tmp_path: Path) -> None:
    """With both references: aggregate.json's gap fields and change share,
    scenario_scores.json's headroom, the headroom and change-share tables after the ranking,
    the page's long ranking and the verdict's two more sentences."""
    import math

    from shipgym_baselines.leaderboard.outputs import terminal_summary

    gap = with_stand_in_references(randomised, tmp_path)
    (pid,) = json.loads((gap / "aggregate.json").read_text())  # oracle_frozen is not ranked
    assert set(pid) == AGGREGATE_KEYS and pid["controller"] == "pid_los"
    assert pid["cost_vs_frozen_gmean"] == pytest.approx(FROZEN)
    assert pid["cost_vs_frozen_gmean_ci95"] == pytest.approx([FROZEN, FROZEN])
    assert pid["prob_beats_frozen"] == 1.0 and pid["gap_trials"] == 6
    closed = math.log(FROZEN) / math.log(FROZEN / STAND_IN)  # log 2 / log 2.5 = 0.756
    assert pid["gap_closed_iqm"] == pytest.approx(closed)
    # the stand-in oracle costs STAND_IN × pid_los's on a trial and on its twin (nominal):
    # the change raises both costs by the same factor, so pid_los's change share is 1
    assert pid["nominal_cost_ratio_gmean"] == pytest.approx(1 / STAND_IN)
    assert pid["change_share_iqm"] == pytest.approx(1.0)
    assert pid["change_share_iqm_ci95"] == pytest.approx([1.0, 1.0])
    assert pid["change_trials"] == pid["share_trials"] == 3  # rudder_aging's trials
    for entry in json.loads((gap / "scenario_scores.json").read_text()):
        assert entry["headroom"] == pytest.approx(FROZEN / STAND_IN)
        assert entry["oracle_frozen_cost"] == pytest.approx(entry["oracle_cost"] * 2.5)
    text = (gap / "leaderboard.md").read_text()
    verdict = text.split("\n\n")[1]
    assert verdict == (
        "`pid_los` is the only ranked controller on the 2 catalogue scenarios, at IQM 1.250 "
        "[1.250, 1.250]. No learned agent is ranked; the failure rate is 0 %. Knowing the "
        "change is worth 2.50× over 6 trials (`oracle_frozen` over `oracle`, geometric mean). "
        "Change share (0 = costs as much as never adapting, 1 = as little as the oracle): "
        "`pid_los` 1.00 [1.00, 1.00]."
    )
    ranking, _ = text.split("## Cost ratio per scenario", 1)
    # the main ranking: the nominal ratio and the change share, not the gap closed
    assert "| 0.00 [0.00, 0.00] | 1.25 [1.25, 1.25] | 1.00 [1.00, 1.00] (3) |" in ranking
    assert "gap closed" not in ranking and "0.76" not in ranking
    shares = ranking.split("### Change share per ship and change family", 1)[1]
    assert "| nomoto2 | rudder aging | 3 | 1.00 |" in shares
    headroom = ranking.split("### Headroom per ship and change family", 1)[1]
    assert (
        "| ship | nominal | rudder aging |\n|---|---|---|\n| nomoto2 | 2.50 (3) | 2.50 (3) |"
        in (headroom)
    )
    assert terminal_summary(gap).startswith(text.split("\n\n")[1])
    html = (gap / "leaderboard.html").read_text()
    assert 'id="headroom"' in html and "2.500<i>3 trials</i>" in html
    assert 'id="change-share"' in html
    long = html[html.index('id="ranking-long-catalogue"') :]
    assert "0.756<i>[0.756, 0.756]</i><i>6 trials</i>" in long[: long.index("</table>")]


def test_the_in_range_split_is_ranked_in_its_own_table(tmp_path: Path) -> None:
    """A smoke-sized run (2 seeds, the in-range scenario on the first only; pid_los, lqr
    and the oracle) on a catalogue, a held-out and an in-range scenario: the in-range
    scenario is its own split in every output, beside the other two, run on its own seeds
    (``run.json``'s ``scenario_seeds``); its oracle reference is read from the shipped
    table, which holds the default suite's in-range trials."""
    from shipgym_baselines.leaderboard.jobs import trials
    from shipgym_baselines.references import shipped_table
    from shipgym_baselines.suite import load_suite

    randomize = load_suite("default").randomize.model_dump(mode="json")
    suite = write_suite(
        tmp_path,
        scenarios=["rudder_aging"],
        heldout_scenarios=1,
        inrange_scenarios=1,
        inrange_seeds=1,
        controllers=["pid_los", "lqr", "oracle"],
        seeds=2,
        randomize=randomize,
    )
    out = tmp_path / "out"
    run(suite, out)
    record = read_run(out)["suite"]
    # every scenario changes: each has a no-change twin of its own, the in-range one's on
    # its seeds
    twins = {s: f"twin:{s}" for s in ("rudder_aging", "heldout:0", "inrange:0")}
    assert record["twins"] == twins
    assert record["scenario_seeds"] == {"inrange:0": [10_000], "twin:inrange:0": [10_000]}
    everything = [(e["scenario"], e["seed"]) for e in read_episodes(out)]
    episodes = [(s, seed) for s, seed in everything if s in record["scenarios"]]
    assert {(s, seed) for s, seed in everything if s not in record["scenarios"]} == {
        (twins[s], seed) for s, seed in episodes
    }
    assert sorted(set(episodes)) == [
        ("heldout:0", 10_000),
        ("heldout:0", 10_001),
        ("inrange:0", 10_000),
        ("rudder_aging", 10_000),
        ("rudder_aging", 10_001),
    ]
    beyond = tmp_path / "beyond"  # an in-range episode on a seed of the others only
    shutil.copytree(out, beyond)
    first = next(e for e in read_episodes(out) if e["scenario"] == "inrange:0")
    with open(beyond / "episodes.jsonl", "a") as fh:
        fh.write(json.dumps({**first, "seed": 10_001}) + "\n")
    with pytest.raises(RunError, match="seed 10001 is not one of the run's seeds of 'inrange:0'"):
        read_episodes(beyond, suite=read_run(beyond)["suite"])
    board = json.loads((out / "aggregate.json").read_text())
    assert all(set(r) == AGGREGATE_KEYS for r in board)
    for r in board:  # the oracle played the twins: every row has its nominal ratio
        assert r["nominal_cost_ratio_gmean"] is not None
        assert r["change_trials"] == (1 if r["split"] == "inrange" else 2)  # its trials
    assert {(r["split"], r["controller"]) for r in board} == {
        (split, controller)
        for split in ("catalogue", "heldout", "inrange")
        for controller in ("pid_los", "lqr")
    }
    assert {r["scenarios"][0] for r in board if r["split"] == "inrange"} == {"inrange:0"}
    rows = json.loads((out / "leaderboard.json").read_text())
    assert {(r["scenario"], r["split"]) for r in rows} == {
        ("rudder_aging", "catalogue"),
        ("heldout:0", "heldout"),
        ("inrange:0", "inrange"),
    }
    scores = json.loads((out / "scenario_scores.json").read_text())
    assert {s["scenario"]: s["split"] for s in scores}["inrange:0"] == "inrange"
    for entry in json.loads((out / "generalisation.json").read_text()):
        assert entry["catalogue_scenarios"] == entry["heldout_scenarios"] == 1
        assert entry["inrange_scenarios"] == 1 and "inrange_ace_L" in entry
    text = (out / "leaderboard.md").read_text()
    tables = [line for line in text.splitlines() if line.startswith("### ") and "(1," in line]
    assert tables == [
        "### Catalogue scenarios (1, the same for every controller)",
        "### Held-out scenarios (1, the same for every controller)",
        "### In-range scenarios, drawn from the training ranges (1, the same for every controller)",
    ]
    assert "## Generalisation: catalogue vs held-out vs in-range scenarios" in text
    assert "(1 catalogue, 1 held-out, 1 in-range)" in text
    assert (out / "ranking_inrange.png").is_file() and (out / "profile_inrange.png").is_file()
    html = (out / "leaderboard.html").read_text()
    assert 'id="ranking-inrange"' in html and "In-range scenarios, drawn from" in html
    (trial,) = trials(Job("oracle", "inrange:0", (10_000,), None, randomize))
    assert shipped_table().lookup(trial, 10_000) is not None  # the default suite's trial


# --- a failing controller is a result ---------------------------------------------------------

#: controllers that fail at their third act of an episode (``Raises`` on seed 10001 only),
#: unless the environment variable ``FIXED`` is set; ``ResetRaises`` fails in ``reset``
BAD_PLUGINS = """
import os
import time

import numpy as np


class _Steer:
    kind = "classical"

    def reset(self, context, seed=None):
        self.calls, self.seed = 0, seed

    def act(self, obs, info):
        self.calls += 1
        rudder = np.clip(np.array([-2.0 * (obs[0] + obs[1]) - 4.0 * obs[3]]), -1.0, 1.0)
        if self.calls == 3 and not os.environ.get("FIXED"):
            return self.wrong(rudder)
        return rudder


class Raises(_Steer):
    name = "raises"

    def wrong(self, rudder):
        if self.seed != 10001:
            return rudder
        raise ValueError("the gain table\\nhas no entry")


class Nan(_Steer):
    name = "nan"

    def wrong(self, rudder):
        return np.array([np.nan])


class NoneAction(_Steer):
    name = "none"

    def wrong(self, rudder):
        return None


class Shape(_Steer):
    name = "shape"

    def wrong(self, rudder):
        return np.zeros(3)


class Slow(_Steer):
    name = "slow"

    def wrong(self, rudder):
        end = time.process_time() + 0.2  # computes: CPU time over the limit
        while time.process_time() < end:
            pass
        return rudder


class ResetRaises(_Steer):
    name = "reset_raises"

    def reset(self, context, seed=None):
        if not os.environ.get("FIXED"):
            raise RuntimeError("no model file")
        super().reset(context, seed)
"""
#: table name → (its failure rate, the start of its episodes' ``error``)
BROKEN = {
    "raises": (0.5, "ValueError: the gain table has no entry"),
    "nan": (1.0, "ValueError: action contains NaN or inf: array([nan])"),
    "none": (1.0, "ValueError: action must be an array of shape (1,), got None"),
    "shape": (1.0, "ValueError: action must be an array of shape (1,), got array([0., 0., 0.])"),
    "slow": (1.0, "the call ran "),
    "reset_raises": (1.0, "RuntimeError: no model file"),
}


def _broken_argv(plugins: Path, out: Path, *extra: str) -> list[str]:
    classes = ["Raises", "Nan", "NoneAction", "Shape", "Slow", "ResetRaises"]
    return [
        "leaderboard",
        "--suite",
        "smoke",
        "--controllers",
        *(f"{plugins}:{c}" for c in classes),
        "--act-timeout",
        "0.05",
        "--out",
        str(out),
        "--workers",
        "1",
        "--no-progress",
        *extra,
    ]


@pytest.fixture(scope="module")
def broken_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, str]:
    """The smoke suite with a controller of each way to fail (and the references): (the
    plug-in file, the run folder, what stderr said)."""
    from shipgym_baselines.cli import main

    root = tmp_path_factory.mktemp("broken")
    plugins = root / "bad.py"
    plugins.write_text(BAD_PLUGINS)
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("SHIPGYM_QUIET", raising=False)  # the failure notices
        mp.delenv("FIXED", raising=False)
        stderr = io.StringIO()
        mp.setattr(sys, "stderr", stderr)
        assert main(_broken_argv(plugins, root / "out")) == 0
    return plugins, root / "out", stderr.getvalue()


def _failed(folder: Path) -> list[dict]:
    return [e for e in read_episodes(folder) if e["termination_reason"].startswith("controller")]


def test_a_leaderboard_of_broken_controllers_finishes_and_ranks_each(
    broken_run: tuple[Path, Path, str],
) -> None:
    _, out, stderr = broken_run
    assert read_run(out)["status"] == "complete"
    board = json.loads((out / "aggregate.json").read_text())
    for split in ("catalogue", "heldout"):
        rows = {r["controller"]: r for r in board if r["split"] == split}
        assert set(rows) == set(BROKEN)
        for name, (rate, _) in BROKEN.items():
            assert rows[name]["failure_rate"] == rate, (split, name)
    failed = _failed(out)
    # every episode of five, one seed of two a scenario of raises; the smoke suite's 3
    # scenarios and the no-change twins of its 2 changing ones, 2 seeds each
    suite = read_run(out)["suite"]
    assert list(suite["twin_scenarios"]) == ["twin:rudder_aging", "twin:heldout:0"]
    assert set(BROKEN) <= set(suite["twin_players"])
    episodes = (len(suite["scenarios"]) + len(suite["twin_scenarios"])) * len(suite["seeds"])
    assert episodes == (3 + 2) * 2
    assert len(failed) == episodes * 5 + episodes // 2
    for episode in failed:
        rate, message = BROKEN[episode["controller"]]
        reason = "controller_timeout" if episode["controller"] == "slow" else "controller_error"
        assert episode["termination_reason"] == reason
        assert episode["error"].startswith(message) and "\n" not in episode["error"]
    assert "`raises`" in (out / "leaderboard.md").read_text()
    assert "raises" in (out / "leaderboard.html").read_text()
    for name in BROKEN:  # the first failure of each, named on stderr
        assert f"shipgym: {name} failed on " in stderr


def test_resume_keeps_the_failed_episodes_and_retry_failed_runs_them_again(
    broken_run: tuple[Path, Path, str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from shipgym_baselines.cli import main

    plugins, source, _ = broken_run
    out = tmp_path / "out"
    shutil.copytree(source, out)
    lines = (out / "episodes.jsonl").read_text()
    monkeypatch.setenv("FIXED", "1")  # the controllers work now
    assert main(_broken_argv(plugins, out, "--resume")) == 0
    assert (out / "episodes.jsonl").read_text() == lines  # nothing run again
    assert len(_failed(out)) == len(_failed(source))
    assert main(_broken_argv(plugins, out, "--resume", "--retry-failed")) == 0
    assert len((out / "episodes.jsonl").read_text().splitlines()) == len(lines.splitlines()) + len(
        _failed(source)
    )
    assert _failed(out) == [] and read_run(out)["status"] == "complete"
    board = json.loads((out / "aggregate.json").read_text())
    assert {r["controller"]: r["failure_rate"] for r in board} == dict.fromkeys(BROKEN, 0.0)
