"""Errors raised for bad user input: each names where the problem is and what it is."""

from __future__ import annotations


class InputError(Exception):
    """Bad user input (a file, a field or an argument); its message is one line."""

    def __init__(self, source: str, where: str, problem: str) -> None:
        self.source = source
        self.where = where
        self.problem = problem
        location = f"{source}: {where}" if where else source
        super().__init__(one_line(f"{location}: {problem}"))


def one_line(text: str) -> str:
    """``text`` with every character that would break or hide a line (a newline, a tab, a
    control character) written as its escape: a name holding one cannot split an error."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


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
