"""Unpickling of scenes and results (the functions their ``__reduce__`` names)."""

from . import _ssn


def restore_scene(text, path, overrides, matrices):
    """A scene from its text, path, values and in-memory matrices."""
    return _ssn.Scene._restore(text, path, overrides, matrices)


def restore_result(kind, doc, arrays):
    """A result from its kind, JSON document and arrays."""
    return _ssn._restore_result(kind, doc, arrays)
