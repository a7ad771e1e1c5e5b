"""The project's error base class."""

from __future__ import annotations


class ShipgymError(Exception):
    """The base of every error the project raises for bad input (a non-physical parameter,
    an unknown scenario, a malformed config, …).

    Subclasses also derive from the built-in they refine (``ValueError``, ``KeyError``), so
    ``except ValueError`` keeps working.  The ``shipgym`` CLI prints these as one line
    (``shipgym: error: <message>``, exit code 2); any other exception is a bug and keeps its
    traceback.
    """
