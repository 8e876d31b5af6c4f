"""Episode videos: the RGB → YUV conversion, byte-identical encodes of the same frames, and
segments joined and split again without re-encoding."""

from __future__ import annotations

import io

import av
import numpy as np

from robocfg.datasets.video import VideoConcat, encode_episode, rgb_to_yuv420p, split_segments

FPS = 10


def frames(seed: int, n: int = 12, size: int = 32) -> np.ndarray:
    """A moving gradient with noise: content an encoder has to work on."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size]
    out = np.stack([np.stack([(x * 8 + k * 5) % 256, (y * 8 + k * 3) % 256, (x + y + k) * 4 % 256], axis=-1)
                    for k in range(n)]).astype(np.int32)
    return np.clip(out + rng.integers(-3, 4, out.shape), 0, 255).astype(np.uint8)


def test_bt601_limited_range_of_known_colours():
    rgb = np.array([[[255, 255, 255], [0, 0, 0]], [[255, 0, 0], [0, 0, 255]]], np.uint8)
    y, cb, cr = rgb_to_yuv420p(rgb)
    assert y.tolist() == [[235, 16], [81, 41]]  # white, black, red, blue (Rec. 601 tables)
    # the 2x2 block's chroma is that of its mean colour (127.5, 63.75, 127.5):
    # Cb = 128 + (-37.797 R - 74.203 G + 112 B) / 255 = 146.55, Cr = 128 + (112 R - 93.786 G - 18.214 B) / 255 = 151.45
    assert cb.tolist() == [[147]] and cr.tolist() == [[151]]


def test_the_same_frames_give_the_same_bytes_whatever_was_encoded_before():
    clips = [frames(s) for s in range(4)]
    first = [encode_episode(c, FPS).data for c in clips]
    for _ in range(2):
        assert [encode_episode(c, FPS).data for c in reversed(clips)][::-1] == first


def test_segments_join_and_split_by_packet_copy(tmp_path):
    clips = [frames(s, n) for s, n in ((1, 7), (2, 10), (3, 5))]
    segs = [encode_episode(c, FPS) for c in clips]
    path = tmp_path / "all.mp4"
    joined = VideoConcat(path, FPS)
    for s in segs:
        joined.append(s)
    joined.close()
    with av.open(str(path)) as c:
        decoded = list(c.decode(video=0))
    assert len(decoded) == 22
    np.testing.assert_allclose([float(f.time) for f in decoded], np.arange(22) / FPS, atol=1e-9)
    got = np.stack([f.to_ndarray(format="rgb24") for f in decoded]).astype(int)
    want = np.concatenate(clips).astype(int)
    err = np.abs(got - want).mean()
    assert err < 0.5 * np.abs(got - want[::-1]).mean()  # lossy, but the pictures in their order
    back = split_segments(path, FPS, [7, 10, 5])

    def packets(data: bytes) -> list[bytes]:
        with av.open(io.BytesIO(data)) as c:
            return [bytes(p) for p in c.demux(video=0) if p.dts is not None]

    assert [packets(b.data) for b in back] == [packets(s.data) for s in segs]
