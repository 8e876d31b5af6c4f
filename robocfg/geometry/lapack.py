"""LAPACK routines from scipy's own f2py wrapper (``scipy.linalg._flapack``) without importing
the ``scipy.linalg`` package.

The IK (``dposv``: Cholesky solve of the Levenberg-Marquardt step) and the min-jerk splines
(``dgtsv``: tridiagonal solve) need one LAPACK call each, but ``import scipy.linalg`` loads
scipy's array-API layer (numpy.f2py, numpy.testing, numpy.ma...): ≈ 0.25 s of CPU of every
fresh process (measured under load 8 on the 2-core laptop: 0.46 s for numpy + scipy.linalg
against 0.20 s for numpy + this). The extension module is loaded from scipy's folder under its
own name, so a later ``import scipy.linalg`` reuses it: the functions are the very objects
``scipy.linalg.lapack`` gives (the same results, bit for bit). scipy's folder is found without
running ``scipy/__init__`` (its version checks import ``subprocess`` and compile regexes: ≈ 0.03 s
of CPU under load 15 on the 2-core laptop, which the first episode does not otherwise pay). Where
that cannot be done (another layout of scipy), ``scipy.linalg.lapack`` is imported as usual.
"""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

_NAME = "scipy.linalg._flapack"


def lapack(name: str) -> Callable[..., Any]:
    """scipy's f2py wrapper of the LAPACK routine ``name`` (e.g. ``"dposv"``)."""
    module = sys.modules.get(_NAME) or _load()
    return getattr(module, name)


def _load() -> Any:
    found = importlib.util.find_spec("scipy")  # locates the package; does not import it
    places = list(found.submodule_search_locations or []) if found is not None else []
    files = []
    if len(places) == 1:
        files = [p for p in (Path(places[0]) / "linalg").glob("_flapack.*") if p.suffix in (".so", ".pyd")]
    spec = importlib.util.spec_from_file_location(_NAME, files[0]) if len(files) == 1 else None
    if spec is None or spec.loader is None:
        import scipy.linalg.lapack

        return scipy.linalg.lapack._flapack
    module = importlib.util.module_from_spec(spec)
    sys.modules[_NAME] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[_NAME]
        raise
    return module
