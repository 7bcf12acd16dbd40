"""``python -m synth``."""

from synth.cli import entry

entry()
