"""One BLAS thread for every solve: the same rounding, so the same generation path, on any
number of cores."""

from __future__ import annotations

import contextlib
import functools
import threading

_BLAS = threading.local()  # depth of one_blas_thread in this thread


@functools.cache
def _blas_limits():
    """threadpoolctl's ``threadpool_limits``, taught CasADi's own copy of OpenBLAS.

    IPOPT's MUMPS calls the OpenBLAS that CasADi ships as ``libcasadi-tp-openblas``, a name
    threadpoolctl does not know; registered here, ``one_blas_thread`` limits it too. A limit
    reaches only the libraries loaded when it is set, and CasADi loads that one with its
    IPOPT plugin, at the first solve: loaded here first, so that the first run of a process
    (every ``rigidfold generate``) solves on one thread as the later runs of a study worker
    do, and takes the same path (before, Huffman's waterbomb on Bezier seed 7 took 268
    solves as a process's first run and 278 after any other).
    """
    import casadi
    import scipy.linalg  # noqa: F401  (SciPy's own OpenBLAS, loaded before the limit)
    from threadpoolctl import OpenBLASController, register, threadpool_limits

    class CasadiOpenBLAS(OpenBLASController):
        filename_prefixes = ("libcasadi-tp-openblas",)

    register(CasadiOpenBLAS)
    casadi.load_nlpsol("ipopt")
    return threadpool_limits


@contextlib.contextmanager
def one_blas_thread():
    """Context manager that runs the BLAS and LAPACK of NumPy, SciPy and IPOPT (MUMPS) on one
    thread.

    Problem (6) has no unique minimiser: F is zero on a family of developable shapes (as
    many directions as the mechanism has DOF), and round-off decides which one IPOPT
    reaches. A multi-threaded BLAS rounds differently for each thread count, so without
    this the same case could take another path on a machine with more cores, or in a shell
    rather than in a study worker (Dask starts workers with one thread); MUMPS inside IPOPT
    does too, from a 21 x 21 grid on. The matrices of the paper's patterns are small, so one
    thread costs no measurable time. Nested uses cost nothing: only the outermost one sets
    the limit (about 1 ms with threadpoolctl). Also a decorator, ``@one_blas_thread()``.
    ``benchmarks/blas_threads.py`` measures all of this.
    """
    depth = getattr(_BLAS, "depth", 0)
    _BLAS.depth = depth + 1
    try:
        if depth:
            yield
        else:
            with _blas_limits()(limits=1, user_api="blas"):
                yield
    finally:
        _BLAS.depth = depth
