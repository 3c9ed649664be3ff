"""Errors raised for bad user input: each names where the problem is and what it is."""

from __future__ import annotations


class InputError(Exception):
    """Bad user input (a file, a field or an argument); its message is one line."""

    def __init__(self, source: str, where: str, problem: str) -> None:
        self.source = source
        self.where = where
        self.problem = problem
        location = f"{source}: {where}" if where else source
        super().__init__(f"{location}: {problem}")


class ScenarioError(InputError):
    """A scenario file is malformed: names the file, the field path and the problem."""


class FieldProblem(ValueError):
    """Raised by a settings object's own validation; the loader adds the file and the path."""

    def __init__(self, field: str, problem: str) -> None:
        self.field = field
        self.problem = problem
        super().__init__(f"{field}: {problem}")


def read_text_file(path, error: type[InputError] = InputError) -> str:
    """A UTF-8 text file's contents; unreadable or binary files raise ``error`` naming it."""
    try:
        return path.read_text(encoding="utf-8")
    except OSError as failure:
        raise error(str(path), "", f"cannot read: {failure.strerror}") from None
    except UnicodeDecodeError:
        raise error(str(path), "", "not UTF-8 text") from None
