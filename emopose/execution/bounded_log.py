"""An append-only log that keeps only its newest entries, so a server that runs for days stays bounded.

Readers keep a cursor (`total` when they start) and ask for what came `since` it; entries that fell out
of the window are simply gone, and `total` keeps counting.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from typing import Generic, TypeVar

T = TypeVar("T")


class BoundedLog(Generic[T]):
    def __init__(self, keep: int = 10_000) -> None:
        if keep < 1:
            raise ValueError(f"a bounded log keeps at least 1 entry, got {keep}")
        self._items: deque[T] = deque(maxlen=keep)
        self.total = 0

    def append(self, item: T) -> None:
        self._items.append(item)
        self.total += 1

    def since(self, cursor: int) -> list[T]:
        """The retained entries appended at or after position `cursor` (a past value of `total`)."""
        return self.read(cursor)[0]

    def read(self, cursor: int) -> tuple[list[T], int]:
        """(the entries since `cursor`, the cursor to read on from), consistent while a writer appends."""
        while True:
            total = self.total
            items = list(self._items)
            if total == self.total:  # no append in between: items end at position total
                return items[max(cursor - (total - len(items)), 0):], total

    def recent(self, count: int) -> list[T]:
        return self.since(self.total - count)

    def __iter__(self) -> Iterator[T]:
        return iter(list(self._items))

    def __len__(self) -> int:
        """Entries retained (at most `keep`); `total` counts every entry ever appended."""
        return len(self._items)
