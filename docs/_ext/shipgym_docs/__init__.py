"""Pages of the shipgym docs generated at build time from the package itself.

At ``builder-inited`` the generators write MyST pages into ``<srcdir>/_generated/`` (ignored by
git): one page per registered env id (:mod:`.envs`, from the env class's docstring), the
scenario catalogue with route figures (:mod:`.scenarios`), one page per registered controller
(:mod:`.controllers`), the ship models' parameter tables (:mod:`.ships`), the command-line
reference (:mod:`.cli`), the recorded
measurements (:mod:`.measurements`), the API reference (:mod:`.api`) and the notebooks as
tutorials (:mod:`.tutorials`).  A page is rewritten only
when its text changes, so that an incremental build rereads only what moved.  The validation
tables (:mod:`.validation`) are not written at build time: they live in ``docs/validation.md``
itself, and a test checks them.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

from sphinx.application import Sphinx

from shipgym_docs import (
    api,
    cli,
    controllers,
    docstrings,
    envs,
    measurements,
    scenarios,
    ships,
    tutorials,
)

GENERATED = "_generated"
GENERATORS = (envs, scenarios, controllers, ships, cli, measurements, tutorials, api)


def generate(app: Sphinx) -> None:
    """Write every generated page under ``<srcdir>/_generated`` and drop stale ones."""
    root = Path(app.srcdir) / GENERATED
    written: set[Path] = set()
    for generator in GENERATORS:
        if generator is api and not app.config.shipgym_docs_api:
            written |= set(api.write_placeholder(root))
            continue
        written |= set(generator.write(root))
    for path in sorted(root.rglob("*"), reverse=True):
        if path.is_file() and path not in written:
            path.unlink()
        elif path.is_dir() and not any(path.iterdir()):
            shutil.rmtree(path)


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_config_value("shipgym_docs_api", True, "env", bool)
    app.connect("builder-inited", generate)
    app.connect("autodoc-process-docstring", docstrings.process_docstring)
    app.connect("autodoc-skip-member", docstrings.skip_foreign)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
