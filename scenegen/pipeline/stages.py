"""The stages after the views as work items: the cross-view stage (view pairs, flow pairs,
rectified stereo frames, board views) and the sequence stage (motion pairs, point tracks, stereo
motion pairs). The driver plans each stage's items (:func:`scenegen.pipeline.crossview.plan_crossview`,
:func:`scenegen.pipeline.sequence.plan_sequence`); they run here one after the other, or on Dask
workers in groups of items that share views (a group shares its views' cached truth and
correspondences: a stage's ``locality`` puts them next to each other, and groups end where that
key changes), each group's files written atomically by the worker and recorded by the driver, its
index entries taken in the plan's order. An item's
bytes do not depend on where it ran or with what else, so both ways give the same dataset
(tests/scenegen/pipeline/test_stage_items_dask.py).

A stage is an entry of :data:`STAGES`: how to plan it, make the context its items share, run one
item, and finish (the index). Adding a stage is one :class:`Stage` and one line there.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from scenegen.dataset.files import FileSink, remove_stale_temp_files
from scenegen.pipeline import crossview, sequence
from scenegen.pipeline.distributed import note_stage_items, shipped_value, worker_scene
from scenegen.pipeline.progress import ViewProgress

#: Item groups per worker: small enough to balance, large enough to share cached truth.
GROUPS_PER_WORKER = 2


class WriterSink:
    """The driver's sink: files go through the dataset writer (recorded at once); ``files``
    lists what the stage wrote."""

    def __init__(self, writer):
        self.writer, self.root = writer, writer.root
        self.files: dict[str, str] = {}

    def write_file(self, rel: str, data: bytes) -> str:
        sha = self.writer.write_file(rel, data)
        self.files[rel] = sha
        return sha


@dataclass(frozen=True)
class Stage:
    """``plan(spec, views, is_complete, built) -> plan | None`` (``plan.items``);
    ``context(spec, complete views, built, sink, plan, spp, seed)``; ``execute(context, item) ->
    index entry``; ``finish(plan, entries, files, writer)``; ``label``: the progress line's;
    ``prepare(spec, writer) -> {path: sha256}``: files the driver writes before the items;
    ``locality(item, position) -> key``: items with equal keys share cached work and run in one
    group, groups taken in key order (``position``: a view name's index among the views); None:
    the plan's own order is the one that shares most."""

    plan: Callable
    context: Callable
    execute: Callable
    finish: Callable
    label: str
    prepare: Callable = lambda spec, writer: {}
    locality: Callable | None = None


def _plan_crossview(spec, views, is_complete, built):
    return crossview.plan_crossview(spec, views, is_complete, has_boards=bool(built.boards))


def _crossview_context(spec, views, built, sink, plan, spp, seed):
    return crossview.CrossviewContext(spec, views, built, sink, spp=spp, seed=seed)


def _sequence_context(spec, views, built, sink, plan, spp, seed):
    return sequence.SequenceContext(spec, views, built, sink, keep_frames=plan.keep_frames)


def _crossview_locality(item, position):
    """A cross-view item's views, as their first and last position: a pair's, flow's and stereo
    frame's items of the same two views share both views' truth points and correspondences."""
    names = [n for n in item[1:] if n is not None]
    return min(position[n] for n in names), max(position[n] for n in names)


def _finish_sequence(plan, entries, files, writer):
    return sequence.finish_sequence(plan, files, writer)


def _prepare_sequence(spec, writer):
    rel = sequence.write_objects_document(spec, writer)
    return {rel: writer.file_sha256(rel)}


STAGES = {
    "crossview": Stage(_plan_crossview, _crossview_context, crossview.execute_crossview_item,
                       crossview.finish_crossview, "cross-view truth", locality=_crossview_locality),
    "sequence": Stage(lambda spec, views, is_complete, built: sequence.plan_sequence(spec, views, is_complete),
                      _sequence_context, sequence.execute_sequence_item, _finish_sequence, "sequence truth",
                      _prepare_sequence),
}


def run_stage(name: str, spec, views, built, writer, *, spp: int, seed: int, variant: str,
              client=None, source=None, progress: bool = False):
    """Plan stage ``name`` on the complete views, run its items (here, or on ``client``'s Dask
    workers, which load ``source``), record their files and finish it. Returns what the stage's
    finish returns (None when the spec asks for nothing)."""
    stage = STAGES[name]
    plan = stage.plan(spec, views, writer.is_complete, built)
    if plan is None:
        return None
    done = [v for v in views if writer.is_complete(v.name)]
    files = dict(stage.prepare(spec, writer))
    with ViewProgress(progress, len(plan.items), label=stage.label, unit="items") as bar:
        if client is None or not plan.items:
            sink = WriterSink(writer)
            ctx = stage.context(spec, done, built, sink, plan, spp, seed)
            entries = []
            for item in plan.items:
                entries.append(stage.execute(ctx, item))
                bar.advance()
            files.update(sink.files)
        else:
            entries = _run_on_workers(name, plan, done, writer, files, client=client, source=source, spp=spp,
                                      seed=seed, variant=variant, on_done=bar.advance,
                                      locality=stage.locality, position={v.name: k for k, v in enumerate(views)})
    return stage.finish(plan, entries, files, writer)


def stage_items_task(name: str, source, out_dir: str, done: tuple[str, ...], plan, items, spp: int, seed: int,
                     variant: str):
    """Dask task: run ``items`` of stage ``name`` in this worker's scene; returns ([entry per
    item], {relative path: sha256} of the files written)."""
    spec, views, built = worker_scene(source, spp, variant)
    names = set(done)
    sink = FileSink(out_dir)
    stage = STAGES[name]
    ctx = stage.context(spec, [v for v in views if v.name in names], built, sink, plan, spp, seed)
    entries = [stage.execute(ctx, item) for item in items]
    note_stage_items(len(items))
    return entries, sink.files


def item_groups(items, n_groups: int, keys=None) -> list[list[int]]:
    """``items`` (their indices) cut into about ``n_groups`` groups of about equal size: in the
    order of ``keys`` (one per item; None: the items' order), a group ending only where the key
    changes (items with one key share cached work)."""
    order = sorted(range(len(items)), key=lambda k: (keys[k], k)) if keys is not None else list(range(len(items)))
    size = max(1, -(-len(items) // max(1, n_groups)))
    groups, group = [], []
    for pos, k in enumerate(order):
        group.append(k)
        last = pos + 1 == len(order)
        if last or (len(group) >= size and (keys is None or keys[order[pos + 1]] != keys[k])):
            groups.append(group)
            group = []
    return groups


def _run_on_workers(name, plan, done, writer, files, *, client, source, spp, seed, variant, on_done, locality,
                    position):
    n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    items = plan.items
    keys = None if locality is None else [locality(item, position) for item in items]
    groups = item_groups(items, GROUPS_PER_WORKER * n_workers, keys)
    out_dir = str(Path(writer.root).resolve())
    names = tuple(v.name for v in done)
    # the spec's source and the plan go to the workers once (tasks returning them), not in every task
    shipped_source, shipped_plan = (client.submit(shipped_value, x, pure=False) for x in (source, plan))
    futures = [client.submit(stage_items_task, name, shipped_source, out_dir, names, shipped_plan,
                             [items[k] for k in g], spp, seed, variant, pure=False) for g in groups]
    entries = [None] * len(items)
    try:
        for fut, group in zip(futures, groups):
            group_entries, group_files = fut.result()
            writer.record_files(group_files)
            files.update(group_files)
            for k, entry in zip(group, group_entries):  # the index lists them in the plan's order
                entries[k] = entry
            for _ in group:
                on_done()
    finally:
        for fut in futures:
            fut.cancel()
        shipped_source.release()
        shipped_plan.release()
    remove_stale_temp_files(out_dir)  # a worker killed mid-write: its task ran again elsewhere
    return entries
