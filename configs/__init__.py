"""The config catalogue, installed as the package data ``shipgym.configs``.

This top-level folder is the single source: ``pyproject.toml`` maps it to
``shipgym/configs``, and :mod:`shipgym.config` finds its YAML files through
:mod:`importlib.resources` (from a wheel or an editable install alike).
"""
