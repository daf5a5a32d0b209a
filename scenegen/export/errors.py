"""The exporters' error (the CLI prints it and exits with status 2)."""


class ExportError(ValueError):
    """The dataset cannot be exported in the requested format (message says why)."""
