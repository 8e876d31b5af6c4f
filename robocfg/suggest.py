"""Near-miss name suggestions ("did you mean ...?")."""

from __future__ import annotations

from collections.abc import Iterable


def closest(name: str, candidates: Iterable[str]) -> str | None:
    """The candidate closest to ``name`` (case-insensitive), or None if nothing is close."""
    import difflib  # here: only a mistake needs it (≈ 3 ms of every process's start otherwise)

    cands = list(candidates)
    lowered = {c.lower(): c for c in cands}
    hits = difflib.get_close_matches(name.lower(), list(lowered), n=1, cutoff=0.6)
    return lowered[hits[0]] if hits else None


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` or the empty string."""
    hit = closest(name, candidates)
    return f"; did you mean {hit!r}?" if hit else ""
