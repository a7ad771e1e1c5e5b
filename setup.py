"""Packaging of what pyproject.toml cannot say: the packages are found on disk, and the
top-level ``configs/`` (the single source of the config catalogue) is mapped in as the
package ``shipgym.configs``, so that :mod:`shipgym.config` finds it through
``importlib.resources`` in a wheel and in an editable install alike.  Package data (the YAML
files, the shipped policies) is listed in pyproject.toml."""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages(include=["shipgym*", "baselines*"]), "shipgym.configs"],
    package_dir={"shipgym.configs": "configs"},
)
