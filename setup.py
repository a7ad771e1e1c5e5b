"""Packaging of what pyproject.toml cannot say: the packages are found on disk, the top-level
``configs/`` (the single source of the config catalogue) is mapped in as the package
``shipgym.configs``, so that :mod:`shipgym.config` finds it through ``importlib.resources`` in
a wheel and in an editable install alike, and the top-level ``baselines/`` folder installs as
the import package ``shipgym_baselines`` (``baselines`` is OpenAI Baselines' import name on
PyPI: installing both would break one of them).  Package data (the YAML files, the shipped
policies, the reference table) is listed in pyproject.toml."""

from setuptools import find_packages, setup

BASELINES = [
    "shipgym_baselines" + name[len("baselines") :]
    for name in find_packages(include=["baselines", "baselines.*"])
]

setup(
    packages=[*find_packages(include=["shipgym", "shipgym.*"]), "shipgym.configs", *BASELINES],
    package_dir={"shipgym.configs": "configs", "shipgym_baselines": "baselines"},
)
