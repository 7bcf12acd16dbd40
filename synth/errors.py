"""One family of errors for bad input.

Every error that a user can cause (a bad spec file, an unparsable transfer
function, a broken data column) is a :class:`SynthError`. Its ``str()`` is one
line naming *where* the problem is (a file, a key, a column) and *what* is
wrong, so the command line can print it as-is and exit with code 2.
"""

from __future__ import annotations

__all__ = ["DataError", "FitError", "ModelError", "NoStabilizingControllerError", "NoStabilizingStartError",
           "OutputExistsError", "SpecError", "SynthError"]


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


class NoStabilizingStartError(SynthError):
    """A search of the controller's bounds found no controller that stabilizes the loop.

    Not bad input: the spec is valid, and the bounds may hold no stabilizing controller at all. The
    message says what was searched; :func:`synth.design.design` turns it into an "undetermined" design
    verdict (exit 3 from the command line), since a search that found nothing proves nothing.

    Examples
    --------
    >>> err = NoStabilizingStartError("600 random controllers in the bounds gave none", where="controller")
    >>> isinstance(err, SynthError), str(err)
    (True, 'controller: 600 random controllers in the bounds gave none')
    """

    def __init__(self, message: str, where: str | None = None, searched: str | None = None) -> None:
        super().__init__(message, where)
        self.searched = searched or self.message  # what the search covered, for the undetermined verdict

    def located(self, where: str) -> NoStabilizingStartError:
        """Return a copy with ``where`` prefixed, keeping what was searched."""
        inner = f"{where}: {self.where}" if self.where else where
        return NoStabilizingStartError(self.message, where=inner, searched=self.searched)


class NoStabilizingControllerError(NoStabilizingStartError):
    """The controller's bounds hold no controller that stabilizes the loop, and ``proof`` says what shows it (an
    exact decomposition of the bounds, not a search): :func:`synth.design.design` answers "infeasible".

    Examples
    --------
    >>> err = NoStabilizingControllerError("no PI in the bounds stabilizes the loop", proof="the D-decomposition")
    >>> isinstance(err, NoStabilizingStartError), err.located("controller").proof
    (True, 'the D-decomposition')
    """

    def __init__(self, message: str, where: str | None = None, searched: str | None = None,
                 proof: str = "") -> None:
        super().__init__(message, where, searched)
        self.proof = proof

    def located(self, where: str) -> NoStabilizingControllerError:
        """Return a copy with ``where`` prefixed, keeping what was searched and the proof."""
        inner = f"{where}: {self.where}" if self.where else where
        return NoStabilizingControllerError(self.message, where=inner, searched=self.searched, proof=self.proof)


class FitError(SynthError, RuntimeError):
    """A fit ran but failed: it diverged, hit the iteration limit, or its result is not a model of the record.

    Not bad input (the command line exits 1, not 2): the record and the options were
    valid, the structure just does not fit them. The message says what failed and what to try.
    Also a ``RuntimeError``, so code that tries several fits and skips the ones that fail at
    run time (the gap attribution's re-fits) keeps doing so.

    Parameters
    ----------
    message : str
        What failed and what to try.
    where : str, optional
        The record (file) the fit was on.
    status : str, optional
        The solver's return status (e.g. IPOPT's ``"Diverging_Iterates"``).
    parameters : dict, optional
        The parameter values the solver ended at (for diagnosis; never a result).

    Examples
    --------
    >>> err = FitError("diverged", where="run.csv", status="Diverging_Iterates", parameters={"K": 2e24})
    >>> str(err), err.status, err.parameters
    ('run.csv: diverged', 'Diverging_Iterates', {'K': 2e+24})
    >>> str(err.located("identify")), err.located("identify").status
    ('identify: run.csv: diverged', 'Diverging_Iterates')
    """

    def __init__(self, message: str, where: str | None = None, status: str | None = None,
                 parameters: dict[str, float] | None = None) -> None:
        super().__init__(message, where)
        self.status = status
        self.parameters = dict(parameters or {})

    def located(self, where: str) -> FitError:
        """Return a copy with ``where`` prefixed, keeping the status and parameters."""
        inner = f"{where}: {self.where}" if self.where else where
        return FitError(self.message, where=inner, status=self.status, parameters=self.parameters)
