"""The JSON of a run folder: a file read back (a one-line :class:`RunError` naming the file
and the line), written atomically through no link, two documents compared key by key
(what differs on ``--resume``), and a metric as strict JSON (±inf as ``"inf"`` /
``"-inf"``, NaN as null) and back."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.errors import RunError
from shipgym_baselines.jsonout import dumps
from shipgym_baselines.records.outfiles import write_bytes


def read_json(file: Path) -> Any:
    """The JSON document of ``file``; a :class:`RunError` naming the file and the line
    where it is not UTF-8 or not JSON, or why it is unreadable."""
    try:
        return json.loads(file.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as exc:
        line = file.read_bytes()[: exc.start].count(b"\n") + 1
        raise RunError(f"{file}: line {line}: not UTF-8 text") from None
    except json.JSONDecodeError as exc:
        raise RunError(f"{file}: line {exc.lineno}: not JSON ({exc.msg})") from None
    except OSError as exc:
        raise RunError(f"{file}: unreadable ({exc.strerror})") from None


def write_json(file: Path, document: Any) -> None:
    """Write atomically, through no link
    (:func:`~shipgym_baselines.records.outfiles.write_bytes`)."""
    write_bytes(file, (dumps(document, indent=2) + "\n").encode())


def as_json(document: Any) -> Any:
    """``document`` as it reads back from JSON (tuples → lists, numpy → Python)."""
    return json.loads(dumps(document))


def differences(old: Any, new: Any, where: str = "") -> list[str]:
    """The dotted keys at which two JSON documents differ, with both values."""
    if isinstance(old, dict) and isinstance(new, dict):
        found = []
        for key in dict.fromkeys([*old, *new]):
            sub = f"{where}.{key}" if where else str(key)
            if key not in old or key not in new:
                side = "now" if key in new else "in the run"
                found.append(f"{sub} only {side}")
            else:
                found += differences(old[key], new[key], sub)
        return found
    if old == new:
        return []
    if isinstance(old, list) and isinstance(new, list):
        return _list_differences(old, new, where or "value")
    return [f"{where or 'value'}: {short_json(old)} in the run, {short_json(new)} now"]


def _item(value: Any) -> str:
    """A list item as a person names it: a mapping by its ``name``, else its JSON."""
    if isinstance(value, dict) and isinstance(value.get("name"), str):
        return value["name"]
    return short_json(value, 30)


def _list_differences(old: list, new: list, where: str) -> list[str]:
    """How two lists differ: the items only in one (by name), else item by item."""
    a, b = [_item(v) for v in old], [_item(v) for v in new]
    if a != b:
        gone, added = [x for x in a if x not in b], [x for x in b if x not in a]
        parts = [f"{', '.join(gone)} only in the run"] if gone else []
        parts += [f"{', '.join(added)} only now"] if added else []
        return [f"{where}: {'; '.join(parts) or 'the same items in another order'}"]
    found = []
    for name, x, y in zip(a, old, new, strict=True):
        found += differences(x, y, f"{where}[{name}]")
    return found


def short_json(value: Any, limit: int = 60) -> str:
    """``value`` as JSON text of at most ``limit`` characters (cut short with "…")."""
    text = json.dumps(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def plain(value: Any) -> Any:
    """A metric as strict JSON: numpy scalars as Python ones, ±inf as "inf"/"-inf", NaN null."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        value = float(value)
        if math.isnan(value):
            return None
        return value if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [plain(v) for v in value]
    return value


def from_plain(value: Any) -> Any:
    """One value as :func:`plain` wrote it, read back: "inf" / "-inf" as ±inf (a mapping's
    values too), the rest as it is."""
    if isinstance(value, dict):
        return {k: from_plain(v) for k, v in value.items()}
    if value == "inf":
        return math.inf
    if value == "-inf":
        return -math.inf
    return value


__all__ = [
    "as_json",
    "differences",
    "from_plain",
    "plain",
    "read_json",
    "short_json",
    "write_json",
]
