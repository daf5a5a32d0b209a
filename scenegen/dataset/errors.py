"""Errors of a dataset folder (the CLI prints them and exits with status 2)."""


class DatasetError(Exception):
    """A dataset directory is not what it should be (not a dataset, wrong format, bad name...)."""


class DatasetMismatchError(DatasetError):
    """Resuming, or re-writing a file, would mix outputs of different runs."""
