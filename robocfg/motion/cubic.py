"""scipy's ``CubicSpline`` (not-a-knot and natural ends) without importing ``scipy.interpolate``.

Importing ``scipy.interpolate`` pulls in ``scipy.optimize``, ``scipy.sparse``, ``scipy.special`` and
``scipy.spatial``: 0.2–1 s of a fresh process, paid by the first pick-place episode of every
process (its straight moves are splines through many waypoints). :class:`CubicSpline` here does
the same arithmetic in the same order — the tridiagonal system solved by LAPACK ``dgtsv`` as
``scipy.linalg.solve_banded`` does, the Hermite coefficients, and ``PPoly``'s evaluation loop
(``_ppoly.evaluate_poly1``: Horner-free powers, derivative prefactors) — so its values are the
same bits as scipy's (tested against ``scipy.interpolate.CubicSpline``), and simulated runs do
not change with it. LAPACK comes from scipy's wrapper (:mod:`robocfg.geometry.lapack`).

Only what robocfg calls: ``x`` (k,) strictly increasing, ``y`` (k, n) along axis 0, k ≥ 4 for
``"not-a-knot"`` and k ≥ 2 for ``"natural"``; ``spline(s, nu)`` for ``nu`` in 0, 1, 2, 3,
extrapolating the end pieces like scipy. Units: whatever ``x`` and ``y`` carry.
"""

from __future__ import annotations

from typing import Literal

import numpy as np


class CubicSpline:
    """A C² cubic through ``(x[i], y[i])``: ``spline(s)``, ``spline(s, nu)`` → (len(s), n)."""

    def __init__(self, x, y, axis: int = 0, bc_type: Literal["not-a-knot", "natural"] = "not-a-knot"):
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        if axis != 0 or y.ndim != 2 or x.ndim != 1 or len(x) != len(y):
            raise ValueError("CubicSpline: x (k,) and y (k, n) along axis 0 only")
        if bc_type not in ("not-a-knot", "natural") or len(x) < (4 if bc_type == "not-a-knot" else 2):
            raise ValueError(f"CubicSpline: {bc_type!r} ends with {len(x)} points are not supported here")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
            raise ValueError("CubicSpline: x and y must be finite")
        dx = np.diff(x)
        if np.any(dx <= 0):
            raise ValueError("CubicSpline: x must be strictly increasing")
        n = len(x)
        dxr = dx.reshape(len(dx), 1)
        slope = np.diff(y, axis=0) / dxr
        A = np.zeros((3, n))  # banded: upper, diagonal, lower
        b = np.empty((n, y.shape[1]), dtype=np.float64)
        A[1, 1:-1] = 2 * (dx[:-1] + dx[1:])
        A[0, 2:] = dx[:-1]
        A[-1, :-2] = dx[1:]
        b[1:-1] = 3 * (dxr[1:] * slope[:-1] + dxr[:-1] * slope[1:])
        if bc_type == "not-a-knot":
            A[1, 0] = dx[1]
            A[0, 1] = x[2] - x[0]
            d = x[2] - x[0]
            b[0] = ((dxr[0] + 2 * d) * dxr[1] * slope[0] + dxr[0] ** 2 * slope[1]) / d
            A[1, -1] = dx[-2]
            A[-1, -2] = x[-1] - x[-3]
            d = x[-1] - x[-3]
            b[-1] = (dxr[-1] ** 2 * slope[-2] + (2 * d + dxr[-1]) * dxr[-2] * slope[-1]) / d
        else:  # natural: second derivative 0 at both ends (scipy's (2, 0.0) conditions)
            zero = np.zeros(y.shape[1])
            A[1, 0] = 2 * dx[0]
            A[0, 1] = dx[0]
            b[0] = -0.5 * zero * dx[0] ** 2 + 3 * (y[1] - y[0])
            A[1, -1] = 2 * dx[-1]
            A[-1, -2] = dx[-1]
            b[-1] = 0.5 * zero * dx[-1] ** 2 + 3 * (y[-1] - y[-2])
        s = _solve_tridiagonal(A, b)
        t = (s[:-1] + s[1:] - 2 * slope) / dxr
        self.x = x
        self._c_by_column: np.ndarray | None = None  # self.c as (4, n, k-1), made on first evaluation
        self.c = np.stack((t / dxr, (slope - s[:-1]) / dxr - t, s[:-1], y[:-1]))  # (4, k-1, n), highest power first

    def __call__(self, xs, nu: int = 0) -> np.ndarray:
        """Values (nu = 0) or the ``nu``-th derivative at ``xs``: shape ``xs.shape + (n,)``."""
        return self.derivatives(xs, (nu,))[0]

    def derivatives(self, xs, nus: tuple[int, ...]) -> list[np.ndarray]:
        """``[spline(xs, nu) for nu in nus]``, the same values bit for bit (C-ordered arrays of
        shape ``xs.shape + (n,)``): :meth:`derivatives_by_column` transposed."""
        xs = np.asarray(xs, dtype=np.float64)
        n = self.c.shape[2]
        return [np.ascontiguousarray(r.T).reshape(*xs.shape, n) for r in self.derivatives_by_column(xs.ravel(), nus)]

    def derivatives_by_column(self, xs, nus: tuple[int, ...]) -> list[np.ndarray]:
        """``[spline(xs, nu).T for nu in nus]`` for 1-D ``xs``: arrays of shape (n, len(xs)), one
        row per column of ``y``, the same values bit for bit as scipy's. scipy's evaluation
        (``res = res + c * z * prefactor`` over the powers, from ``res = 0.0``) runs along the
        points, with the pieces' lookup, their coefficients at ``xs`` (one gather of all of them)
        and the powers of the local coordinate made once and each sum built in place."""
        flat = np.asarray(xs, dtype=np.float64)
        if flat.ndim != 1:
            raise ValueError("CubicSpline.derivatives_by_column: 1-D xs only")
        if self._c_by_column is None:  # (order, n, pieces): each coefficient's rows run along the points
            self._c_by_column = np.ascontiguousarray(self.c.transpose(0, 2, 1))
        c = self._c_by_column
        order, n = c.shape[0], c.shape[1]
        # np.clip's bounds checks cost more than the search on these small arrays; the same ints
        i = np.minimum(np.maximum(np.searchsorted(self.x, flat, side="right") - 1, 0), len(self.x) - 2)
        s = flat - self.x[i]
        coefs = c.take(i, axis=2)  # (order, n, points): coefs[order - kp - 1] multiplies s**kp
        nan = np.isnan(flat)
        has_nan = bool(nan.any())
        if nus == (0, 1) and order == 4:  # what a played move asks: both sums at once
            both = _values_and_slopes(coefs, s)
            if has_nan:
                both[:, :, nan] = np.nan
            return [both[0], both[1]]
        powers: list[np.ndarray | None] = [None]  # s**m built as (s*s)*s...; None stands for scipy's exact 1.0
        out = []
        tmp: np.ndarray | None = None
        for nu in nus:
            res: np.ndarray | None = None
            for kp in range(nu, order):
                prefactor = 1.0
                for k in range(kp, kp - nu, -1):
                    prefactor *= k
                coef = coefs[order - kp - 1]
                m = kp - nu  # scipy: res = res + c * z * prefactor, z = s**m (x * 1.0 is x, bit for bit)
                while len(powers) <= m:
                    powers.append(s if len(powers) == 1 else powers[-1] * s)
                z = powers[m]
                # term = coef * z * prefactor, into a new array (the first term becomes res) or tmp
                buf = None if res is None else tmp
                if z is not None:
                    term = np.multiply(coef, z, out=buf)
                    if prefactor != 1.0:
                        term *= prefactor
                elif prefactor != 1.0:
                    term = np.multiply(coef, prefactor, out=buf)
                else:
                    term = coef  # a view of coefs: never written to
                if res is None:  # scipy starts from res = 0.0: term + 0.0
                    if term is coef:
                        res = coef + 0.0
                    else:
                        term += 0.0
                        res = term
                    if tmp is None:
                        tmp = np.empty_like(res)
                else:
                    res += term
            if res is None:
                res = np.zeros((n, len(flat)))
            if has_nan:
                res[:, nan] = np.nan  # scipy: NaN in, NaN out (every derivative)
            out.append(res)
        return out


_SLOPE_FACTORS = np.array([1.0, 2.0])[:, None, None]  # (value, slope) prefactors of the s term ...
_SLOPE_FACTORS_2 = np.array([1.0, 3.0])[:, None, None]  # ... and of the s² term (x * 1.0 is x, bit for bit)


def _values_and_slopes(coefs: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``derivatives_by_column``'s loop for nus (0, 1) of a cubic, the two sums stacked (2, n, N):
    values ``((c3 + 0.0) + c2·s) + c1·s²) + c0·s³`` and slopes ``((c2 + 0.0) + (c1·s)·2) + (c0·s²)·3``
    (``coefs`` = [c0, c1, c2, c3] gathered at the points, highest power first, ``s`` the local
    coordinate): each term and each sum the same operations in the same order as the loop."""
    out = coefs[2:4][::-1] + 0.0  # [c3, c2] + 0.0
    term = coefs[1:3][::-1] * s  # [c2·s, c1·s]
    term *= _SLOPE_FACTORS
    out += term
    s2 = s * s
    np.multiply(coefs[0:2][::-1], s2, out=term)  # [c1·s², c0·s²]
    term *= _SLOPE_FACTORS_2
    out += term
    out[0] += coefs[0] * (s2 * s)
    return out


def _solve_tridiagonal(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``scipy.linalg.solve_banded((1, 1), A, b)`` as scipy calls it: LAPACK ``dgtsv``."""
    from robocfg.geometry.lapack import lapack

    _, _, _, x, info = lapack("dgtsv")(A[2, :-1], A[1, :], A[0, 1:], b, 1, 1, 1, 1)
    if info != 0:
        raise np.linalg.LinAlgError("CubicSpline: singular system")
    return x
