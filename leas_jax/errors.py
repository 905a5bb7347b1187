"""Errors shared by the package: the command line turns them into one-line messages."""


class LeasError(Exception):
    """Base class of the errors this package raises on bad input."""


class UsageError(LeasError):
    """Bad command-line or API input; `leas` prints it on one line and exits with code 2."""


class TerrainError(LeasError):
    """Invalid terrain file or terrain input; the message names file, key and value.

    Defined here, beside the other errors, so that every terrain module (model, loader,
    export) raises it without importing another; `leas_jax.terrain` re-exports it.
    """
