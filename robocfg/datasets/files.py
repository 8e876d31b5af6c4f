"""The file series of a LeRobot v3.0 dataset: when a new file starts (writing), where each file
is (reading).

LeRobot v3.0 keeps many episodes in one file and starts a new one when the current file would
reach a size limit (lerobot 0.4.4, ``LeRobotDataset._save_episode_data`` / ``_save_episode_video``
and ``LeRobotDatasetMetadata._save_episode_metadata``); file ``f`` of chunk ``c`` is
``chunk-{c:03d}/file-{f:03d}``, and after ``chunks_size`` files a new chunk directory begins
(``update_chunk_file_indices``). The limits are written into ``meta/info.json``
(``chunks_size``, ``data_files_size_in_mb``, ``video_files_size_in_mb``; lerobot's defaults 1000,
100 and 200). Three series roll over independently: the data parquet files, the episode metadata
files (both at ``data_files_size_in_mb``) and each camera's video files (``video_files_size_in_mb``).

The rule, per series: an episode goes into the current file unless that file already holds an
episode and its size with the episode's would reach the limit (``>=``, lerobot's comparison);
then it starts the next file. An episode larger than the limit gets a file of its own. Sizes are
counted, not read back from disk, so where files are cut depends only on the episodes in order
(a merge of workers' shards cuts where one process does): a data or metadata episode counts the
Arrow size of its rows (close to the uncompressed parquet size lerobot's ``aggregate_datasets``
compares, ``get_parquet_file_size_in_mb``; lerobot's recorder compares the file's size on disk,
which compressible data such as depth keeps below the count), a video episode the bytes of its
own MP4 segment (lerobot adds the episode's MP4 file size to the current file's size the same way). 1 MB = 2**20 bytes, as lerobot's ``get_file_size_in_mb``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

MB = 1 << 20  # bytes in lerobot's "MB" (get_file_size_in_mb divides by 1024**2)
MAX_CHUNKS_SIZE = 1000  # file-{:03d}: more files a chunk would no longer sort in order (lerobot globs sorted names)
_CHUNK_FILE = re.compile(r"chunk-(\d+)/file-(\d+)\.(parquet|mp4)$")


@dataclass(frozen=True)
class FileLimits:
    """When a new file starts: a data (or episode metadata) file holds at most
    ``data_files_size_in_mb`` MB, a video file ``video_files_size_in_mb`` MB (1 MB = 2**20
    bytes); a chunk directory holds ``chunks_size`` files. Defaults: lerobot 0.4.4's
    (``DEFAULT_CHUNK_SIZE``, ``DEFAULT_DATA_FILE_SIZE_IN_MB``, ``DEFAULT_VIDEO_FILE_SIZE_IN_MB``)."""

    chunks_size: int = 1000
    data_files_size_in_mb: float = 100
    video_files_size_in_mb: float = 200

    def __post_init__(self) -> None:
        if not 1 <= self.chunks_size <= MAX_CHUNKS_SIZE:
            raise ValueError(f"chunks_size must be 1..{MAX_CHUNKS_SIZE} (three-digit file names), got {self.chunks_size}")
        for name in ("data_files_size_in_mb", "video_files_size_in_mb"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive, got {getattr(self, name)}")

    def info(self) -> dict[str, int | float]:
        """The ``meta/info.json`` entries (whole numbers written as integers, as lerobot writes them)."""
        return {"chunks_size": self.chunks_size, "data_files_size_in_mb": _number(self.data_files_size_in_mb),
                "video_files_size_in_mb": _number(self.video_files_size_in_mb)}


def _number(x: float) -> int | float:
    return int(x) if float(x).is_integer() else float(x)


def next_file(chunk: int, file: int, chunks_size: int) -> tuple[int, int]:
    """The (chunk, file) after ``(chunk, file)``: lerobot's ``update_chunk_file_indices``."""
    return (chunk + 1, 0) if file == chunks_size - 1 else (chunk, file + 1)


@dataclass
class FileSeries:
    """Where the next episode of one series of files goes (data, episode metadata, or one
    camera's videos): the current ``chunk`` and ``file``, the bytes counted in it and its episodes."""

    limit_mb: float
    chunks_size: int
    chunk: int = 0
    file: int = 0
    size: int = 0  # bytes counted in the current file
    episodes: int = 0  # episodes in the current file

    def rolls(self, nbytes: int) -> bool:
        """An episode of ``nbytes`` would start a new file."""
        return self.episodes > 0 and self.size + nbytes >= self.limit_mb * MB

    def add(self, nbytes: int) -> bool:
        """Count an episode of ``nbytes`` into the series (starting the next file first when
        :meth:`rolls`); True when it started a new file."""
        rolled = self.rolls(nbytes)
        if rolled:
            self.chunk, self.file = next_file(self.chunk, self.file, self.chunks_size)
            self.size = self.episodes = 0
        self.size += nbytes
        self.episodes += 1
        return rolled


def chunk_file(path: Path) -> tuple[int, int]:
    """(chunk, file) of a ``…/chunk-CCC/file-FFF.parquet|mp4`` path."""
    m = _CHUNK_FILE.search(Path(path).as_posix())
    if m is None:
        raise ValueError(f"{path}: not a chunk-…/file-… path")
    return int(m.group(1)), int(m.group(2))


def series_files(folder: Path, suffix: str = "parquet") -> list[Path]:
    """The files ``folder/chunk-*/file-*.<suffix>`` in (chunk, file) order."""
    return sorted(Path(folder).glob(f"chunk-*/file-*.{suffix}"), key=chunk_file)
