"""Every run time and rank quoted in the prose of the README and ``docs/*.md`` is recorded in
``docs/measurements.json`` (``docs/_ext/shipgym_docs/measurements.py``): a number cannot be
typed into prose without its command, commit and machine."""

from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "docs" / "_ext"))

from shipgym_docs import measurements  # noqa: E402

HOW = (
    "Record each number in docs/measurements.json: add its value with its unit (e.g. "
    '"521 s", "0.3 ms", "17 min"; a rank as a bare number, kind "rank") to the entry '
    "of the run that measured it, or a new entry {id, kind, values, what, command, commit, "
    "machine, quoted_in}, and list this file in its quoted_in. A number that is a target or "
    "a setting, not a measurement, goes into not_measurements as the phrase that holds it "
    '(e.g. "inside the 10 minutes") with its reason. See docs/docs-site.md, \'Numbers in '
    "the prose'."
)


def test_every_run_time_and_rank_in_the_prose_is_recorded() -> None:
    missing = measurements.check()
    lines = [f"{q.file}:{q.line}: {q.text!r} ({q.kind}) in: {q.sentence[:160]}" for q in missing]
    assert not missing, (
        "numbers quoted in prose but not recorded:\n" + "\n".join(lines) + ("\n" + HOW)
    )


SAMPLE = """# A page

The default run took 512 s wall and 1,011 CPU s at f91dd5d; the quick
suite ≈ 2–5 CPU minutes. With Ts = 0.5 s the ship turns after 30 s.
The agent ranks 14th of 18, `ppo` is #3, inside the 10-minute target.

| run | wall |
|---|---|
| main | 999 s |

```bash
time shipgym leaderboard  # took 777 s
```
"""


def test_the_extractor_finds_run_times_and_ranks_in_prose_only() -> None:
    found = {(q.kind, q.value, q.unit) for q in measurements.quotes(SAMPLE, "page.md")}
    assert found == {
        ("time", 512.0, "s"),
        ("time", 1011.0, "s"),
        ("time", 2.0, "min"),
        ("time", 5.0, "min"),
        ("rank", 14.0, ""),
        ("rank", 3.0, ""),
    }
    # not quoted: a setting (Ts = 0.5 s), a sentence not about run time (30 s), the
    # "10-minute" target, a table row (999 s) and a code block (777 s)


def test_an_unrecorded_number_is_reported_and_an_excused_one_is_not() -> None:
    registry = {
        "measurements": [
            {
                "id": "run",
                "kind": "time",
                "values": ["512 s", "1011 s", "2 min", "5 min"],
                "quoted_in": ["page.md"],
            },
            {"id": "rank", "kind": "rank", "values": [14], "quoted_in": ["page.md"]},
        ],
        "not_measurements": [],
    }
    quoted = measurements.quotes(SAMPLE, "page.md")
    (missing,) = measurements.unrecorded(quoted, registry)
    assert (missing.kind, missing.value, missing.text) == ("rank", 3.0, "#3")
    registry["not_measurements"] = [{"phrase": "`ppo` is #3", "reason": "an example"}]
    assert measurements.unrecorded(quoted, registry) == []
    # a recorded value counts only for the files that quote it, and with its unit
    elsewhere = measurements.quotes(SAMPLE, "other.md")
    assert len(measurements.unrecorded(elsewhere, registry)) == 6 - 1
    registry["measurements"][0]["values"] = ["512 ms", "1011 s", "2 min", "5 min"]
    assert [q.value for q in measurements.unrecorded(quoted, registry)] == [512.0]


def test_the_registry_is_well_formed() -> None:
    registry = measurements.load()
    ids = [e["id"] for e in registry["measurements"]]
    assert len(ids) == len(set(ids)) >= 30
    for entry in registry["measurements"]:
        for key in ("kind", "values", "what", "command", "commit", "machine", "quoted_in"):
            assert entry.get(key), (entry["id"], key)
        assert entry["kind"] in ("time", "rank"), entry["id"]
        for value in entry["values"]:
            _number, unit = measurements.parse_value(value)
            assert (unit == "") == (entry["kind"] == "rank"), (entry["id"], value)
            assert unit in ("", "s", "ms", "µs", "min", "h"), (entry["id"], value)
        for file in entry["quoted_in"]:
            assert (REPO / file).is_file(), (entry["id"], file)
    for entry in registry["not_measurements"]:
        assert entry["phrase"] and entry["reason"], entry


def test_the_registry_page_lists_every_measurement() -> None:
    registry = measurements.load()
    text = measurements.page(registry)
    for entry in registry["measurements"]:
        assert f"| {entry['id']} |" in text
