"""Exceptions raised by coseg. Every error of the library arrives as one of these, with the
library's message (which names the file or shape concerned)."""


class CosegError(Exception):
    """Base class of every coseg error."""


class InputError(CosegError, ValueError):
    """Bad input: a malformed mesh or array (wrong shape, NaN, index out of range), a bad
    option value, or a stage that cannot run on these shapes."""


class FileError(CosegError, OSError):
    """A file or directory could not be read or written."""


__all__ = ["CosegError", "InputError", "FileError"]
