"""The response cache: a write that fails is logged and leaves nothing behind; planning goes on."""

from __future__ import annotations

import logging

from emopose.llm.cache import ResponseCache, cache_key


def test_a_round_trip(tmp_path):
    cache, key = ResponseCache(tmp_path), cache_key({"model": "m", "messages": ["hi"]})
    assert cache.get(key) is None
    cache.put(key, "answer", {"model": "m"})
    assert cache.get(key) == "answer"


def test_a_failed_write_is_logged_and_cleaned_up(tmp_path, caplog):
    cache, key = ResponseCache(tmp_path), cache_key({"model": "m"})
    cache._path(key).mkdir(parents=True)  # the entry's name is taken by a folder: the final rename fails
    with caplog.at_level(logging.WARNING, logger="emopose.llm.cache"):
        cache.put(key, "answer")
    assert "could not write" in caplog.text
    assert cache.get(key) is None
    assert not list(cache._path(key).parent.glob(".tmp-*")), "the half-written file is removed"


def test_an_unwritable_cache_folder_is_logged(tmp_path, caplog):
    blocker = tmp_path / "cache"
    blocker.write_text("a file where the cache folder should be")
    with caplog.at_level(logging.WARNING, logger="emopose.llm.cache"):
        ResponseCache(blocker).put(cache_key({"model": "m"}), "answer")
    assert "could not write" in caplog.text
