"""One family of errors for bad input.

Every error that a user can cause (a bad spec file, an unparsable transfer
function, a broken data column) is a :class:`SynthError`. Its ``str()`` is one
line naming *where* the problem is (a file, a key, a column) and *what* is
wrong, so the command line can print it as-is and exit with code 2.
"""

from __future__ import annotations

__all__ = ["DataError", "ModelError", "OutputExistsError", "SpecError", "SynthError"]


class SynthError(Exception):
    """Bad input, reported as one line: ``<where>: <what is wrong>``.

    Parameters
    ----------
    message : str
        What is wrong, in plain words.
    where : str, optional
        The file, key or column the problem is in (for example
        ``"specs/x4.yaml:12: requirements[1].band"``).

    Examples
    --------
    >>> str(SynthError("band must be increasing", where="spec.yaml: requirements[0].band"))
    'spec.yaml: requirements[0].band: band must be increasing'
    """

    def __init__(self, message: str, where: str | None = None) -> None:
        self.message = " ".join(str(message).split())
        self.where = where
        super().__init__(self.message)

    def __str__(self) -> str:
        return f"{self.where}: {self.message}" if self.where else self.message

    def located(self, where: str) -> SynthError:
        """Return a copy of this error with ``where`` prefixed.

        Examples
        --------
        >>> str(ModelError("improper").located("plant.tf"))
        'plant.tf: improper'
        """
        inner = f"{where}: {self.where}" if self.where else where
        return type(self)(self.message, where=inner)


class SpecError(SynthError):
    """A spec file is missing, unreadable or invalid."""


class ModelError(SynthError):
    """A transfer function or controller expression is invalid."""


class DataError(SynthError):
    """A measured record is unusable (missing column, NaN, non-increasing time, ...)."""


class OutputExistsError(SynthError):
    """Writing would overwrite a file that synth did not write."""
