"""Damage to a file's bytes, shared by the fuzz tests (``tests/test_fuzz_*.py``)."""

from __future__ import annotations

import random


def byte_damage(data: bytes, rng: random.Random, kinds: tuple[str, ...]) -> tuple[bytes, str]:
    """``data`` damaged in one of ``kinds`` (drawn by ``rng``, in that order, so that a seed
    gives the same mutants): "cut" short, a "byte" changed, bytes not UTF-8 ("latin-1"), a
    UTF-8 byte order mark ("bom"), a "nul" byte, "empty"; a kind this function does not
    know is returned as it is, for the caller: (``data``, the kind). Returns (bytes, what
    was done)."""
    how = rng.choice(kinds)
    k = rng.randrange(len(data))
    if how == "cut":
        return data[:k], f"cut at byte {k}"
    if how == "byte":
        return data[:k] + bytes([rng.randrange(256)]) + data[k + 1 :], f"byte {k} changed"
    if how == "latin-1":
        return data[:k] + b"\xe9\xff" + data[k:], f"bytes not UTF-8 at {k}"
    if how == "bom":
        return b"\xef\xbb\xbf" + data, "UTF-8 byte order mark"
    if how == "nul":
        return data[:k] + b"\0" + data[k:], f"a NUL byte at {k}"
    if how == "empty":
        return b"", "empty file"
    return data, how
