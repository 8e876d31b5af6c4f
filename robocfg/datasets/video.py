"""Episode videos encoded one by one and joined by copying packets, never re-encoding.

Each episode's frames of one camera are encoded on their own (H.264, yuv420p, a keyframe every
2 frames, no B-frames, one encoder thread), so its packets depend on nothing but its frames: the
same episode gives the same bytes whichever process encodes it and whatever episodes came before.
The RGB → YUV 4:2:0 conversion is done here in numpy (BT.601, limited range: what decoders assume
for an untagged stream) and every byte of the encoder's input planes is written: handing RGB to
the codec's own converter gave, now and then, a different bitstream for the same frames in
another process.
A dataset's camera file is then the episodes' packets back to back, their timestamps shifted by
the frames before them (LeRobot v3 joins its per-episode videos the same way). That is what
makes a dataset written by several workers and merged identical, byte for byte, to the one a
single process writes.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING, Final

import numpy as np

if TYPE_CHECKING:
    from av.container import OutputContainer
    from av.packet import Packet
    from av.video.stream import VideoStream

VIDEO_CODEC: Final = "libx264"
# rc-lookahead=0 (which also turns macroblock-tree rate control off): with lookahead, x264 gave
# the same frames a different bitstream now and then within one process (it depended on what the
# process had done before); without it the bytes are a function of the frames alone.
ENCODER_OPTIONS = {"g": "2", "crf": "23", "preset": "veryfast", "bframes": "0", "threads": "1",
                   "x264-params": "rc-lookahead=0"}


@dataclass(frozen=True)
class EncodedVideo:
    """One episode of one camera: an MP4 file (bytes) holding its ``frames`` frames, frame i at
    time i / fps s."""

    data: bytes
    frames: int


def encode_episode(frames: np.ndarray, fps: int) -> EncodedVideo:
    """Encode ``frames`` ((T, H, W, 3) uint8 RGB, H and W even) as a standalone MP4 at ``fps`` Hz."""
    import av

    buf = io.BytesIO()
    with av.open(buf, "w", format="mp4") as out:
        stream = out.add_stream(VIDEO_CODEC, rate=fps, options=dict(ENCODER_OPTIONS))
        stream.width, stream.height, stream.pix_fmt = int(frames.shape[2]), int(frames.shape[1]), "yuv420p"
        stream.time_base = Fraction(1, fps)
        for i, rgb in enumerate(frames):
            f = yuv420p_frame(rgb)
            f.pts = i
            out.mux(stream.encode(f))
        out.mux(stream.encode(None))
    return EncodedVideo(buf.getvalue(), int(frames.shape[0]))


def rgb_to_yuv420p(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Y (H, W), Cb and Cr (H/2, W/2) of an (H, W, 3) uint8 RGB image: ITU-R BT.601, limited range
    (Y 16..235, chroma 16..240), chroma from the mean of each 2x2 block. Exact and the same in
    every process (float64 arithmetic, rounding half up)."""
    x = np.asarray(rgb, dtype=np.float64)
    r, g, b = x[..., 0], x[..., 1], x[..., 2]
    y = 16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0
    h, w = x.shape[0] // 2, x.shape[1] // 2
    m = x[: 2 * h, : 2 * w].reshape(h, 2, w, 2, 3).mean(axis=(1, 3))
    cb = 128.0 + (-37.797 * m[..., 0] - 74.203 * m[..., 1] + 112.0 * m[..., 2]) / 255.0
    cr = 128.0 + (112.0 * m[..., 0] - 93.786 * m[..., 1] - 18.214 * m[..., 2]) / 255.0
    return _byte(y), _byte(cb), _byte(cr)


def _byte(c: np.ndarray) -> np.ndarray:
    """Values rounded half up and clipped to 0..255, as uint8."""
    return np.clip(np.floor(c + 0.5), 0, 255).astype(np.uint8)


def yuv420p_frame(rgb: np.ndarray):
    """A yuv420p ``av.VideoFrame`` of an RGB image, every byte of its planes written (row padding
    zeroed), so the encoder never sees memory left over from elsewhere."""
    import av

    frame = av.VideoFrame(int(rgb.shape[1]), int(rgb.shape[0]), "yuv420p")
    for plane, data in zip(frame.planes, rgb_to_yuv420p(rgb), strict=True):
        buf = np.frombuffer(memoryview(plane), dtype=np.uint8).reshape(plane.height, plane.line_size)
        buf[:, plane.width:] = 0
        buf[:, : plane.width] = data
    return frame


class VideoConcat:
    """One MP4 built from episode segments appended in order (packets copied; timestamps shifted
    by the frames already in the file, exactly: the shift is computed in fractions)."""

    def __init__(self, path: Path, fps: int):
        self.path, self.fps = Path(path), fps
        self.frames = 0
        self._out: OutputContainer | None = None
        self._stream: VideoStream | None = None

    def append(self, seg: EncodedVideo) -> None:
        import av

        if self._out is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._out = av.open(str(self.path), "w")
        out = self._out
        with av.open(io.BytesIO(seg.data), "r") as src:
            s = src.streams.video[0]
            if self._stream is None:
                self._stream = out.add_stream_from_template(s)
            shift = _ticks(self.frames, self.fps, s)
            for pkt in src.demux(s):
                if pkt.dts is None:  # the demuxer's empty flush packet
                    continue
                _shift(pkt, shift)
                pkt.stream = self._stream
                out.mux(pkt)
        self.frames += seg.frames

    def close(self) -> None:
        if self._out is not None:
            self._out.close()
            self._out = None


def split_segments(path: Path, fps: int, lengths: list[int]) -> list[EncodedVideo]:
    """The episodes of a file written by :class:`VideoConcat`, ``lengths[i]`` frames each in
    order, back as standalone segments (packets copied, timestamps shifted back to 0)."""
    import av

    segs: list[EncodedVideo] = []
    with av.open(str(path)) as src:
        s = src.streams.video[0]
        packets = [p for p in src.demux(s) if p.dts is not None]
        start = 0
        for n in lengths:
            buf = io.BytesIO()
            with av.open(buf, "w", format="mp4") as out:
                o = out.add_stream_from_template(s)
                shift = _ticks(start, fps, s)
                for pkt in packets[start:start + n]:  # no B-frames: one packet per frame, in order
                    _shift(pkt, -shift)
                    pkt.stream = o
                    out.mux(pkt)
            segs.append(EncodedVideo(buf.getvalue(), n))
            start += n
    return segs


def _ticks(frames: int, fps: int, stream: VideoStream) -> int:
    """The time of ``frames`` frames at ``fps`` in ticks of ``stream``'s time base (exact)."""
    if stream.time_base is None:
        raise ValueError("video stream without a time base")
    return int(Fraction(frames, fps) / stream.time_base)


def _shift(pkt: Packet, ticks: int) -> None:
    """Move a packet's timestamps by ``ticks`` (its stream's time base)."""
    if pkt.pts is not None:
        pkt.pts += ticks
    if pkt.dts is not None:
        pkt.dts += ticks
