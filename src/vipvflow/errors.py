"""Errors a user sees as one clear line (the CLI prints them without a traceback)."""


class VipvError(Exception):
    """Base class of errors caused by input or configuration, not by a bug."""


class ConfigError(VipvError):
    """A configuration file has a wrong key or value."""


class InputError(VipvError):
    """An input data file is unreadable or wrong; the message names file and place."""


def accept_hint(finding: str) -> str:
    """How a user accepts a plausibility *finding* that is right after all (docs/checks.md)."""
    return f"(if it is right after all: --accept {finding}, or checks.accept: [{finding}])"
