"""Point clouds from RGB-D captures: fuse views, crop to the workspace, voxel-downsample, and
estimate outward normals (PCA over k nearest neighbours, scipy KD-tree). World frame, metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

NORMAL_NEIGHBOURS = 16


@dataclass
class Cloud:
    """``points`` (N, 3) m; ``labels`` (N,) PyBullet body id of each point; ``viewpoints`` (N, 3)
    the camera position that saw it; ``normals`` (N, 3) unit outward normals (zeros until
    :func:`estimate_normals`); ``curvature`` (N,) surface variation λ₀/(λ₀+λ₁+λ₂) of the
    neighbourhood (0 on a plane, up to 1/3; high at edges and corners)."""

    points: np.ndarray
    labels: np.ndarray
    viewpoints: np.ndarray
    normals: np.ndarray | None = None
    curvature: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.points)

    def select(self, mask: np.ndarray) -> Cloud:
        return Cloud(self.points[mask], self.labels[mask], self.viewpoints[mask],
                     None if self.normals is None else self.normals[mask],
                     None if self.curvature is None else self.curvature[mask])

    @staticmethod
    def concat(clouds: list[Cloud]) -> Cloud:
        return Cloud(np.concatenate([c.points for c in clouds]) if clouds else np.zeros((0, 3)),
                     np.concatenate([c.labels for c in clouds]) if clouds else np.zeros(0, np.int64),
                     np.concatenate([c.viewpoints for c in clouds]) if clouds else np.zeros((0, 3)))


def from_rgbd(rgbd) -> Cloud:
    """The valid pixels of one :class:`~robocfg.sim.camera.RGBD` as a cloud."""
    ok = np.isfinite(rgbd.depth) & np.all(np.isfinite(rgbd.points), axis=-1)
    pts = rgbd.points[ok]
    return Cloud(pts, rgbd.seg[ok].astype(np.int64), np.broadcast_to(rgbd.eye, pts.shape).copy())


def crop(cloud: Cloud, lo, hi) -> Cloud:
    """Points inside the axis-aligned box [lo, hi] (m)."""
    P = cloud.points
    m = np.all((np.asarray(lo) <= P) & (np.asarray(hi) >= P), axis=1)
    return cloud.select(m)


def voxel_downsample(cloud: Cloud, size: float) -> Cloud:
    """One point per occupied voxel of edge ``size`` (m), per label: the centroid of its points
    (labels are kept apart so an object's edge does not blend into the table)."""
    if len(cloud) == 0:
        return cloud
    keys = np.floor(cloud.points / size).astype(np.int64)
    keys = np.column_stack([keys, cloud.labels])
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    k = len(counts)
    pts = np.zeros((k, 3))
    vps = np.zeros((k, 3))
    np.add.at(pts, inverse, cloud.points)
    np.add.at(vps, inverse, cloud.viewpoints)
    labels = np.zeros(k, np.int64)
    labels[inverse] = cloud.labels
    return Cloud(pts / counts[:, None], labels, vps / counts[:, None])


def estimate_normals(cloud: Cloud, k: int = NORMAL_NEIGHBOURS) -> Cloud:
    """Unit normals by PCA of the ``k`` nearest neighbours among points of the same label,
    oriented towards the camera that saw the point (so they point out of the surface)."""
    from scipy.spatial import cKDTree

    normals = np.zeros_like(cloud.points)
    curvature = np.zeros(len(cloud.points))
    for lab in np.unique(cloud.labels):
        idx = np.flatnonzero(cloud.labels == lab)
        P = cloud.points[idx]
        if len(P) < 3:
            continue
        kk = min(k, len(P))
        _, nb = cKDTree(P).query(P, kk)
        Q = P[nb] - P[nb].mean(axis=1, keepdims=True)
        cov = np.einsum("nki,nkj->nij", Q, Q)
        vals, vecs = np.linalg.eigh(cov)
        n = vecs[:, :, 0]
        curvature[idx] = vals[:, 0] / np.maximum(vals.sum(axis=1), 1e-18)
        flip = np.einsum("ij,ij->i", n, cloud.viewpoints[idx] - P) < 0
        n[flip] *= -1
        normals[idx] = n
    cloud.normals = normals
    cloud.curvature = curvature
    return cloud


def save_cloud(cloud: Cloud, path: Path) -> Path:
    """Write ``.npz`` (points, normals, labels, viewpoints) or ASCII ``.ply`` (x y z nx ny nz label)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    normals = cloud.normals if cloud.normals is not None else np.zeros_like(cloud.points)
    if path.suffix.lower() == ".npz":
        np.savez_compressed(path, points=cloud.points, normals=normals, labels=cloud.labels,
                            viewpoints=cloud.viewpoints)
    elif path.suffix.lower() == ".ply":
        # trimesh writes PLY for meshes, but not a face-less cloud with normals and a label per
        # point (its PointCloud has no vertex attributes; export_ply fails on a Trimesh without
        # faces), so the ASCII PLY header is written here and numpy writes the rows.
        header = "\n".join(["ply", "format ascii 1.0", f"element vertex {len(cloud)}",
                            *(f"property float {a}" for a in ("x", "y", "z", "nx", "ny", "nz")),
                            "property int label", "end_header"])
        table = np.column_stack([cloud.points, normals, cloud.labels])
        np.savetxt(path, table, fmt=["%.6f"] * 6 + ["%d"], header=header, comments="")
    else:
        raise ValueError(f"--save-cloud needs a .npz or .ply file name, got {path.name!r}")
    return path
