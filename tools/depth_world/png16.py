"""16-bit greyscale PNG writer and reader (zlib and struct only).

The writer uses the Sub filter on every row (the difference to the pixel two bytes left, which
suits smooth depth) and zlib level 9, so the same image always gives the same bytes. The
reader takes what this writer makes and other non-interlaced 16-bit greyscale PNGs (filters
0-4); it is for the tests and tools, never for pliant, which decodes with libpng.
"""
import struct
import zlib

import numpy as np


def _chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def write(path, image):
    img = np.ascontiguousarray(image, dtype=">u2")
    h, w = img.shape
    raw = img.view(np.uint8).reshape(h, 2 * w)
    sub = raw.copy()
    sub[:, 2:] = raw[:, 2:] - raw[:, :-2]  # uint8 arithmetic wraps modulo 256, as PNG's filter does
    rows = np.hstack([np.ones((h, 1), dtype=np.uint8), sub])
    data = b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 0, 0, 0, 0))
    data += _chunk(b"IDAT", zlib.compress(rows.tobytes(), 9)) + _chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else (b if pb <= pc else c)


def read(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, w = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 16 or colour != 0 or interlace != 0:
                raise ValueError(f"{path}: not a 16-bit greyscale non-interlaced PNG")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    rows = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(h, 2 * w + 1)
    out = np.zeros((h, 2 * w), dtype=np.int64)
    prev = np.zeros(2 * w, dtype=np.int64)
    for y in range(h):
        ftype, line = rows[y, 0], rows[y, 1:].astype(np.int64)
        cur = np.zeros(2 * w, dtype=np.int64)
        if ftype in (0, 2):
            cur = (line + (prev if ftype == 2 else 0)) % 256
        else:
            for x in range(2 * w):
                a = cur[x - 2] if x >= 2 else 0
                c = prev[x - 2] if x >= 2 else 0
                pred = {1: a, 3: (a + prev[x]) // 2, 4: _paeth(a, prev[x], c)}[ftype]
                cur[x] = (line[x] + pred) % 256
        out[y], prev = cur, cur
    return (out[:, 0::2] * 256 + out[:, 1::2]).astype(np.uint16)
