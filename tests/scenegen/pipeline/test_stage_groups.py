"""How the driver cuts a stage's items into groups for Dask workers (scenegen.pipeline.stages):
every item once, items that share cached work (equal locality keys) never split, about equal
sizes, and the cross-view stage's key puts a pair and the flow of the same two views together."""
from __future__ import annotations

from scenegen.pipeline.stages import STAGES, item_groups


def _check_partition(groups, n_items):
    flat = [k for g in groups for k in g]
    assert sorted(flat) == list(range(n_items))  # every item exactly once


def test_without_keys_groups_are_consecutive_runs_of_the_plan():
    groups = item_groups(list(range(18)), 4)
    _check_partition(groups, 18)
    assert groups == [[0, 1, 2, 3, 4], [5, 6, 7, 8, 9], [10, 11, 12, 13, 14], [15, 16, 17]]


def test_items_with_one_key_stay_in_one_group_in_key_order():
    # a plan listing 9 pairs, then the 9 flows of the same views: keys (first view, last view)
    keys = [(k, k + 1) for k in range(9)] * 2
    groups = item_groups(list(range(18)), 4, keys)
    _check_partition(groups, 18)
    assert len(groups) <= 4
    for g in groups:
        assert [keys[k] for k in g] == sorted(keys[k] for k in g)
    group_of = {k: n for n, g in enumerate(groups) for k in g}
    for k in range(9):
        assert group_of[k] == group_of[k + 9]  # pair k and flow k together
    assert max(map(len, groups)) - min(map(len, groups)) <= 2  # about equal sizes
    # a group is cut only between keys: the keys of consecutive groups do not overlap
    for a, b in zip(groups, groups[1:]):
        assert max(keys[k] for k in a) < min(keys[k] for k in b)


def test_one_key_for_everything_gives_one_group():
    groups = item_groups(list(range(7)), 3, [(0, 0)] * 7)
    assert groups == [list(range(7))]


def test_crossview_locality_joins_the_items_of_the_same_views():
    position = {"a": 0, "b": 1, "c": 2}
    key = STAGES["crossview"].locality
    assert key(("pair", "a", "b"), position) == key(("flow", "b", "a"), position) == key(("stereo", "a", "b"), position)
    assert key(("targets", "b", None), position) == (1, 1)
    assert key(("pair", "a", "b"), position) < key(("pair", "b", "c"), position)
    assert STAGES["sequence"].locality is None  # its plan's order already moves each target's scene once
