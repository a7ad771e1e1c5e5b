#!/usr/bin/env bash
# CI: the wheel works outside the checkout (docs/getting-started.md, "The wheel check").
# Builds the wheel, installs it into a fresh venv in a temporary folder (torch==2.13.0
# first, as the README does, then the wheel with the `rl` extra so the learned rows run),
# and from an empty temporary working folder makes every registered env, runs the smoke
# leaderboard (learned rows included) and the liu2019 reproduction.  pip's cache makes the
# second install cheap.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
PYTHON="${PYTHON:-python3}"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
step() { printf '\n== wheel check: %s (%ds)\n' "$1" "$SECONDS"; }

step "build the wheel (from a copy of the sources: no stale build/ of the checkout in it)"
SRC="$WORK/src"
mkdir -p "$SRC"
tar -C "$ROOT" --exclude=./.git --exclude=./.venv --exclude=./results --exclude=./build \
    --exclude='*.egg-info' --exclude=__pycache__ --exclude=.pytest_cache --exclude=.ruff_cache \
    -cf - . | tar -C "$SRC" -xf -
"$PYTHON" -m venv "$WORK/venv"
VENV="$WORK/venv/bin"
"$VENV/pip" wheel "$SRC" --no-deps --quiet -w "$WORK/dist"
WHEEL="$(ls "$WORK"/dist/shipgym-*.whl)"

step "install it into a fresh venv: torch first, then the wheel with [rl]"
"$VENV/pip" install --quiet torch==2.13.0
"$VENV/pip" install --quiet "${WHEEL}[rl]"

RUN="$(mktemp -d -p "$WORK")"
cd "$RUN"  # outside the checkout: nothing of it on the path
step "every registered env from $RUN"
"$VENV/python" - "$ROOT" <<'PY'
import sys
from pathlib import Path

import gymnasium as gym

import shipgym_baselines
import shipgym

root = Path(sys.argv[1]).resolve()
for module in (shipgym, shipgym_baselines):
    where = Path(module.__file__).resolve()
    assert root not in where.parents, f"{module.__name__} imported from the checkout: {where}"
ids = sorted(i for i in gym.registry if i.startswith("ShipPathFollow"))
assert len(ids) >= 5, ids
for env_id in ids:
    gym.make(env_id).reset(seed=0)
    print("ok", env_id)
PY

step "shipgym leaderboard --suite smoke"
"$VENV/shipgym" leaderboard --suite smoke --out leaderboard --no-progress --json > rows.json
"$VENV/python" - <<'PY'
import json

rows = json.load(open("rows.json"))
learned = [r for r in rows if r["controller"] == "ppo"]
assert learned and all(r["kind"] == "learned" and r["ace"] is not None for r in learned), learned
print(len(rows), "rows,", len(learned), "ppo rows")
PY
test -s leaderboard/leaderboard.md

step "shipgym reproduce liu2019 --seeds 1"
"$VENV/shipgym" reproduce liu2019 --out reproduce --seeds 1 --no-progress > reproduce.md
test -s reproduce/liu2019.json
step "done"
