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


class DepthStats:
    """Running statistics of depth images (m) over every pixel of every frame, as one figure per
    statistic of shape (1, 1) (it broadcasts against the (H, W) frames): min, max, mean and std
    exact (float64 sums, episodes added in order), quantiles from a histogram of 1 mm bins (the
    bin's centre, within min..max). ``count`` is the number of frames."""

    BIN = 0.001  # m

    def __init__(self) -> None:
        self.frames = 0
        self.pixels = 0
        self.sum = self.sumsq = 0.0
        self.lo, self.hi = np.inf, -np.inf
        self.hist = np.zeros(0, dtype=np.int64)

    def add(self, depth: np.ndarray) -> None:
        """``depth``: (T, H, W) float32, m."""
        x = np.asarray(depth, dtype=np.float64).reshape(-1)
        if not x.size:
            return
        self.frames += int(depth.shape[0])
        self.pixels += int(x.size)
        self.sum += float(x.sum())
        self.sumsq += float(np.square(x).sum())
        self.lo, self.hi = min(self.lo, float(x.min())), max(self.hi, float(x.max()))
        counts = np.bincount(np.maximum(np.floor(x / self.BIN), 0).astype(np.int64))
        if len(counts) > len(self.hist):
            self.hist = np.pad(self.hist, (0, len(counts) - len(self.hist)))
        self.hist[: len(counts)] += counts

    def result(self) -> dict[str, list]:
        n = self.pixels
        mean = self.sum / n
        std = float(np.sqrt(max(self.sumsq / n - mean * mean, 0.0)))
        cdf = np.cumsum(self.hist) / n
        out = {"min": self.lo, "max": self.hi, "mean": mean, "std": std}
        out.update({_qkey(q): float(np.clip((int(np.searchsorted(cdf, q)) + 0.5) * self.BIN, self.lo, self.hi))
                    for q in QUANTILES})
        res: dict[str, list] = {k: [[float(v)]] for k, v in out.items()}
        res["count"] = [self.frames]
        return res
