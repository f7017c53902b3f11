"""The one family of user errors that rigidfold raises.

:class:`RigidfoldError` is what the library raises where what it was given cannot be used: a
surface or pattern spec, a file (FOLD, SVG, mesh), an option value, a design bound. Its
message is one sentence that names what was received and, where there is one, what to do
instead. It is a ``ValueError``, so code that catches ``ValueError`` catches it too; the
command line prints it as one line and exits 2::

    import rigidfold
    from rigidfold.generate.specs import case_from_specs

    try:
        case = case_from_specs("dome", "grid:1500x900")
    except rigidfold.RigidfoldError as exc:
        print(exc)  # the pattern's triangle count, and the limit

Errors of the libraries underneath (NumPy, SciPy, CasADi) and broken invariants of
rigidfold's own code are not in the family.
"""

from __future__ import annotations


class RigidfoldError(ValueError):
    """A user error: input that rigidfold cannot use, named in a message a user can act on."""
