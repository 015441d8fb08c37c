"""User-facing errors.

Everything that is the user's input being wrong (a missing bag, a bad option,
an invalid scenario field) raises :class:`VicDrakeError` with a message that
names what is wrong and what is allowed. The command line prints the message
and exits with status 2 instead of a traceback.
"""


class VicDrakeError(ValueError):
    """Bad input: the message names the offending item and what is allowed."""


class DataNotFoundError(VicDrakeError, FileNotFoundError):
    """The paper's measurements (or one file of them) are not where expected."""
