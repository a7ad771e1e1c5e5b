"""The JSON of a run folder (:mod:`shipgym_baselines.records.jsonfiles`): a file read back
or refused in one line, the differences of two documents, a metric as strict JSON and
back."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.jsonfiles import (
    as_json,
    differences,
    from_plain,
    plain,
    read_json,
    short_json,
    write_json,
)


def test_a_document_written_reads_back_as_json_gives_it(tmp_path: Path) -> None:
    document = {"seeds": (1, 2), "value": np.float64(0.5), "count": np.int64(3)}
    write_json(tmp_path / "run.json", document)
    assert read_json(tmp_path / "run.json") == as_json(document)
    assert as_json(document) == {"seeds": [1, 2], "value": 0.5, "count": 3}


@pytest.mark.parametrize(
    ("data", "problem"),
    [
        (b'{\n"a": \xff}', "line 2: not UTF-8 text"),
        (b'{"a": 1,\n\n', "line 3: not JSON (Expecting property name enclosed in double quotes)"),
    ],
)
def test_a_file_that_is_not_json_names_its_line(tmp_path: Path, data: bytes, problem: str) -> None:
    file = tmp_path / "run.json"
    file.write_bytes(data)
    with pytest.raises(RunError) as refused:
        read_json(file)
    assert str(refused.value) == f"{file}: {problem}"


def test_differences_name_the_keys_and_list_items_by_name() -> None:
    old = {"seeds": [1, 2], "controllers": [{"name": "pid_los", "kind": "classical"}], "a": 1}
    new = {"seeds": [1, 3], "controllers": [{"name": "pid_los", "kind": "learned"}], "b": 1}
    assert differences(old, new) == [
        "seeds: 2 only in the run; 3 only now",
        'controllers[pid_los].kind: "classical" in the run, "learned" now',
        "a only in the run",
        "b only now",
    ]
    assert differences([{"name": "x"}], [{"name": "y"}]) == ["value: x only in the run; y only now"]
    assert differences([1, 2], [2, 1]) == ["value: the same items in another order"]
    assert differences(old, old) == []


def test_short_json_is_cut_to_its_limit() -> None:
    assert short_json("abc") == '"abc"'
    assert short_json(list(range(40)), 10) == "[0, 1, 2,…"


def test_a_metric_reads_back_through_strict_json() -> None:
    values = {"t_c": math.inf, "low": -math.inf, "nan": math.nan, "ok": np.bool_(True)}
    written = plain(values)
    assert written == {"t_c": "inf", "low": "-inf", "nan": None, "ok": True}
    json.dumps(written, allow_nan=False)  # strict JSON
    back = {k: from_plain(v) for k, v in written.items()}
    assert back == {"t_c": math.inf, "low": -math.inf, "nan": None, "ok": True}
