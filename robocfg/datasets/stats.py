"""Feature statistics in LeRobot's ``stats.json`` form: min, max, mean, std, count and the
quantiles q01, q10, q50, q90, q99 per vector entry; images per colour channel on [0, 1] with
shape (3, 1, 1), computed exactly from a 256-bin histogram of the uint8 values."""

from __future__ import annotations

import numpy as np

QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)


def _qkey(q: float) -> str:
    return f"q{round(q * 100):02d}"


def vector_stats(x: np.ndarray) -> dict[str, list]:
    """Stats of (N, D) (or (N,)) values, per entry."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 1:
        x = x[:, None]
    out = {"min": x.min(0), "max": x.max(0), "mean": x.mean(0), "std": x.std(0)}
    out.update({_qkey(q): np.quantile(x, q, axis=0) for q in QUANTILES})
    res: dict[str, list] = {k: v.tolist() for k, v in out.items()}
    res["count"] = [int(x.shape[0])]
    return res


class ImageStats:
    """Running per-channel histogram of RGB frames (uint8)."""

    def __init__(self) -> None:
        self.hist = np.zeros((3, 256), dtype=np.int64)
        self.frames = 0

    def add(self, frames: np.ndarray) -> None:
        """``frames``: (T, H, W, 3) uint8."""
        for c in range(3):
            self.hist[c] += np.bincount(frames[..., c].reshape(-1), minlength=256)
        self.frames += int(frames.shape[0])

    def result(self) -> dict[str, list]:
        v = np.arange(256) / 255.0
        n = self.hist.sum(1)
        mean = (self.hist * v).sum(1) / n
        std = np.sqrt(np.maximum((self.hist * v**2).sum(1) / n - mean**2, 0.0))
        cdf = np.cumsum(self.hist, 1) / n[:, None]
        out = {"min": [v[np.nonzero(h)[0][0]] for h in self.hist], "max": [v[np.nonzero(h)[0][-1]] for h in self.hist],
               "mean": mean, "std": std}
        out.update({_qkey(q): [v[int(np.searchsorted(cdf[c], q))] for c in range(3)] for q in QUANTILES})
        res: dict[str, list] = {k: np.asarray(val, float).reshape(3, 1, 1).tolist() for k, val in out.items()}
        res["count"] = [self.frames]
        return res
