"""Outcome and status codes <-> words: ``rocksweep.vocab.outcomes`` (kept for imports)."""

from __future__ import annotations

from rocksweep.vocab.outcomes import (  # noqa: F401
    OUTCOME_WORDS,
    STATUS_MEANING,
    STATUS_WORDS,
    outcome_word,
    status_words,
)
