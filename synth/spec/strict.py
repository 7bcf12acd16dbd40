"""The base of every spec block: a strict, frozen pydantic model, and the transfer-function check.

Strict means an unknown key is an error (``extra="forbid"``); frozen means a validated spec is
not changed afterwards.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict

from synth.errors import ModelError
from synth.plant import Plant

__all__ = ["StrictModel", "check_transfer_function"]


class StrictModel(BaseModel):
    """A spec block: unknown keys are errors and the validated block is frozen.

    Examples
    --------
    >>> class Block(StrictModel):
    ...     gain: float = 1.0
    >>> Block(gain=2).gain
    2.0
    >>> from pydantic import ValidationError
    >>> try:
    ...     Block(gian=2)
    ... except ValidationError as exc:
    ...     print(exc.errors()[0]["type"])
    extra_forbidden
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def check_transfer_function(text: str | None) -> str | None:
    """Validator body: ``text`` must parse as a proper transfer function (None passes).

    Parameters
    ----------
    text : str or None
        A transfer function such as ``"23*(s+0.43)/((s+9.6)*(s+0.54))"``.

    Returns
    -------
    str or None
        ``text`` unchanged.

    Raises
    ------
    ValueError
        With the parser's one-line message (pydantic turns it into a located error).

    Examples
    --------
    >>> check_transfer_function("1/(s+1)")
    '1/(s+1)'
    >>> check_transfer_function("(s+1)^2/(s+1)")
    Traceback (most recent call last):
    ...
    ValueError: transfer function '(s+1)^2/(s+1)' is improper (numerator degree 2 > denominator degree 1); ...
    """
    if text is not None:
        try:
            Plant.from_string(text)
        except ModelError as exc:
            raise ValueError(exc.message) from None
    return text
