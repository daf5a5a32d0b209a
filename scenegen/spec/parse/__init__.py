"""YAML -> :class:`~scenegen.spec.model.SceneSpec`, one module per section.

:mod:`.scene` reads the top level and calls, in order, :mod:`.render`, :mod:`.materials`,
:mod:`.cameras` (with :mod:`.optics` and :mod:`.imaging`), :mod:`.rigs`, :mod:`.objects` (with
:mod:`.transforms`), :mod:`.lights`, :mod:`.views`, :mod:`.crossview` and :mod:`.variation`.
Each is a set of functions of the YAML node and an immutable :class:`.context.ParseContext`;
:mod:`.read` reads a value's default, unit and range from its dataclass field. Every failure is a
:class:`~scenegen.errors.SpecError` with file, line and field path.
"""
