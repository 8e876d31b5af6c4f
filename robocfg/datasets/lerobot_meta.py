"""The metadata files of a LeRobot v3.0 dataset and the series of its files: writing
``meta/episodes`` (rolled over as the data files are), ``meta/tasks.parquet`` and the JSON files;
reading back every episode's metadata row and the data files, in order.

LeRobot (0.4.4, ``load_nested_dataset``) reads every ``chunk-*/file-*.parquet`` of
``meta/episodes`` and of ``data`` in sorted order and concatenates them, so all files of a series
share one schema and hold consecutive rows: episodes in order, each wholly in one file.
"""

from __future__ import annotations

import json
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from robocfg.datasets.files import FileLimits, FileSeries, series_files

EPISODES_PATH = "meta/episodes/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"


def write_episodes(root: Path, episodes: list[dict], limits: FileLimits) -> None:
    """``meta/episodes``: one table of every episode's row (so one schema), cut into files where
    the rows reach ``limits.data_files_size_in_mb`` (lerobot rolls its episode metadata over at
    the data files' limit); each row's ``meta/episodes/chunk_index`` and ``file_index`` name its file."""
    if not episodes:
        write_table(pa.table({"episode_index": pa.array([], pa.int64())}),
                    root / EPISODES_PATH.format(chunk_index=0, file_index=0))
        return
    table = pa.Table.from_pylist(episodes)
    files = FileSeries(limits.data_files_size_in_mb, limits.chunks_size)
    where = []
    for i in range(table.num_rows):
        files.add(table.slice(i, 1).nbytes)
        where.append((files.chunk, files.file))
    for col, values in (("meta/episodes/chunk_index", [c for c, _ in where]),
                        ("meta/episodes/file_index", [f for _, f in where])):
        table = table.set_column(table.schema.get_field_index(col), col, pa.array(values, pa.int64()))
    start = 0
    for i in range(1, len(where) + 1):
        if i == len(where) or where[i] != where[start]:
            chunk, file = where[start]
            write_table(table.slice(start, i - start), root / EPISODES_PATH.format(chunk_index=chunk, file_index=file))
            start = i


def read_episodes(root: Path) -> pa.Table:
    """Every episode's metadata row, in order (all ``meta/episodes`` files)."""
    return _concat([pq.read_table(p) for p in series_files(Path(root) / "meta/episodes")])


def data_files(root: Path) -> list[Path]:
    """The data parquet files, in order."""
    return series_files(Path(root) / "data")


def read_data(root: Path, columns: list[str] | None = None) -> pa.Table:
    """Every frame's row (all data files, in order); ``columns``: only these."""
    return _concat([pq.read_table(p, columns=columns) for p in data_files(root)])


def _concat(tables: list[pa.Table]) -> pa.Table:
    if not tables:
        raise FileNotFoundError("no parquet file")
    return tables[0] if len(tables) == 1 else pa.concat_tables(tables)


def write_table(table: pa.Table, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(table, path)


def write_tasks(tasks: dict[str, int], path: Path) -> None:
    """``tasks.parquet`` as pandas writes a DataFrame indexed by the task string (LeRobot reads it
    with ``pandas.read_parquet`` and looks tasks up by index)."""
    names = sorted(tasks, key=lambda t: tasks[t])
    meta = {"index_columns": ["__index_level_0__"],
            "column_indexes": [{"name": None, "field_name": None, "pandas_type": "unicode", "numpy_type": "object",
                                "metadata": {"encoding": "UTF-8"}}],
            "columns": [{"name": "task_index", "field_name": "task_index", "pandas_type": "int64", "numpy_type": "int64",
                         "metadata": None},
                        {"name": None, "field_name": "__index_level_0__", "pandas_type": "unicode",
                         "numpy_type": "object", "metadata": None}],
            "creator": {"library": "pyarrow", "version": pa.__version__}, "pandas_version": "2.2.3"}
    table = pa.table({"task_index": pa.array([tasks[t] for t in names], pa.int64()),
                      "__index_level_0__": pa.array(names, pa.string())})
    write_table(table.replace_schema_metadata({b"pandas": json.dumps(meta).encode()}), path)


def write_json(path: Path, obj: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(obj, indent=2) + "\n")
