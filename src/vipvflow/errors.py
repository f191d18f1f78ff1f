"""Errors a user sees as one clear line (the CLI prints them without a traceback)."""


class VipvError(Exception):
    """Base class of errors caused by input or configuration, not by a bug."""


class ConfigError(VipvError):
    """A configuration file has a wrong key or value."""


class InputError(VipvError):
    """An input data file is unreadable or wrong; the message names file and place."""
