"""Composing a YAML document safely: SafeLoader's composer, refusing while it composes what a
hostile document could use to crash or stall a reader, each with its file and line:

* tags SafeLoader cannot construct (``!!python/name:...``, ``!custom``): nothing is constructed;
* nesting deeper than :data:`MAX_DEPTH` (the composer and the readers recurse once per level);
* aliases that refer to themselves, and alias expansions deeper than :data:`MAX_DEPTH` or larger
  than :data:`MAX_EXPANDED_NODES` (an "alias bomb");
* characters YAML does not allow (NUL, other control characters: a binary file).
"""
from __future__ import annotations

import yaml

from scenegen.errors import SpecError

#: Deepest nesting of mappings and lists a document may have, aliases expanded. Specs and gate
#: files nest about 8 deep; the YAML composer and every reader here recurse once per level, so a
#: deeper (hostile) document would exhaust Python's stack instead of failing with a message.
MAX_DEPTH = 64
#: Most nodes a document may expand to when aliases are followed. Readers walk the expanded tree,
#: so a 200-byte "alias bomb" (9 levels of 9 aliases = 387 million nodes) would run for hours;
#: 4 million is more than any document within the spec's size limit holds without aliases.
MAX_EXPANDED_NODES = 4_000_000
#: Tags a document may carry explicitly: YAML's own (``!!str``, ``!!int``, ...). Anything else
#: (``!!python/name:...``, ``!custom``) is refused where it is written: nothing is constructed.
SAFE_TAGS = frozenset(t for t in yaml.SafeLoader.yaml_constructors if t is not None)
_YAML_TAG = "tag:yaml.org,2002:"


class SafeComposer(yaml.SafeLoader):
    """SafeLoader that refuses, while composing, nesting deeper than MAX_DEPTH and tags that
    SafeLoader cannot construct (so a hostile document fails with its line, never with a
    RecursionError or a ConstructorError later)."""

    def __init__(self, text: str, file: str):
        super().__init__(text)
        self._file, self._depth = file, 0

    def compose_node(self, parent, index):
        event = self.peek_event()
        if not isinstance(event, yaml.AliasEvent):
            tag = getattr(event, "tag", None)
            if tag is not None and tag != "!" and tag not in SAFE_TAGS:
                shown = "!!" + tag[len(_YAML_TAG):] if tag.startswith(_YAML_TAG) else tag
                raise SpecError(f"the YAML tag {shown!r} is not allowed (only plain YAML is read: "
                                "mappings, lists, strings, numbers, true/false, null; nothing is "
                                "constructed from tags)", file=self._file,
                                line=event.start_mark.line + 1)
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            self._depth += 1
            if self._depth > MAX_DEPTH:
                raise SpecError(f"nesting deeper than {MAX_DEPTH} levels of mappings and lists "
                                "(a scene spec nests about 8)", file=self._file,
                                line=event.start_mark.line + 1)
            try:
                return super().compose_node(parent, index)
            finally:
                self._depth -= 1
        return super().compose_node(parent, index)


def check_expansion(root: yaml.Node | None, file: str) -> None:
    """Refuse aliases that refer to themselves (a cycle) and documents whose expanded tree (aliases
    followed) is deeper than MAX_DEPTH or larger than MAX_EXPANDED_NODES. Iterative: no recursion."""
    if root is None:
        return
    size: dict[int, int] = {}
    depth: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        children = _children(node)
        if done:
            on_path.discard(key)
            size[key] = 1 + sum(size[id(c)] for c in children)
            depth[key] = 1 + max((depth[id(c)] for c in children), default=0)
            if size[key] > MAX_EXPANDED_NODES:
                raise SpecError(f"the document expands to more than {MAX_EXPANDED_NODES:,} values "
                                "when its aliases (*name) are followed", file=file,
                                line=node.start_mark.line + 1)
            if depth[key] > MAX_DEPTH + 1:
                raise SpecError(f"nesting deeper than {MAX_DEPTH} levels of mappings and lists "
                                "when aliases (*name) are followed", file=file,
                                line=node.start_mark.line + 1)
            continue
        if key in size:
            continue
        if key in on_path:
            raise SpecError("an alias (*name) refers to a mapping or list that contains it "
                            "(a recursive structure)", file=file, line=node.start_mark.line + 1)
        on_path.add(key)
        stack.append((node, True))
        for c in children:
            if id(c) in on_path:
                raise SpecError("an alias (*name) refers to a mapping or list that contains it "
                                "(a recursive structure)", file=file, line=c.start_mark.line + 1)
            if id(c) not in size:
                stack.append((c, False))


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [n for kv in node.value for n in kv]
    return []



def compose(text: str, file: str) -> tuple[yaml.SafeLoader, yaml.Node | None]:
    """(the loader, for constructing scalars; the root node or None for an empty document).
    Every failure is a SpecError naming ``file`` and, where known, the line."""
    try:
        loader = SafeComposer(text, file)
        try:
            root = loader.get_single_node()
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        what = " ".join(p for p in (e.context, e.problem) if p)
        raise SpecError(f"invalid YAML: {what}", file=file,
                        line=mark.line + 1 if mark else None) from None
    except yaml.reader.ReaderError as e:  # a character YAML does not allow (NUL, ...)
        line = text.count("\n", 0, e.position) + 1 if isinstance(text, str) else None
        char = chr(e.character) if isinstance(e.character, int) else e.character
        raise SpecError(f"invalid YAML: the character {char!r} is not allowed in YAML text "
                        "(is this a binary file?)", file=file, line=line) from None
    except yaml.YAMLError as e:
        raise SpecError(f"invalid YAML: {e}", file=file) from None
    check_expansion(root, file)
    return loader, root
