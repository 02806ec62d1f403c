#!/usr/bin/env python3
"""png-diff.py A.png B.png [THRESHOLD] — how many pixels of two same-sized 8-bit RGB/RGBA PNGs
differ: in any channel at all, and by more than THRESHOLD (default 16) in some channel; plus the
largest channel difference and the number of pixels that differ from the corner pixel (the
background) in each image, so a blank image cannot pass as a match. Standard library only (zlib),
since the machines that compare viewer screenshots (docs/MEASURING.md) need not have Pillow."""
import struct
import sys
import zlib


def read_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"png-diff: {path}: not a PNG file")
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or color not in (2, 6) or interlace:
                sys.exit(f"png-diff: {path}: only 8-bit RGB/RGBA, non-interlaced PNGs are read")
            bpp = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        ftype, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    pixels = [row[x * bpp:x * bpp + 3] for row in rows for x in range(width)]
    return width, height, pixels


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    threshold = int(sys.argv[3]) if len(sys.argv) == 4 else 16
    wa, ha, a = read_png(sys.argv[1])
    wb, hb, b = read_png(sys.argv[2])
    if (wa, ha) != (wb, hb):
        sys.exit(f"png-diff: sizes differ: {wa}x{ha} against {wb}x{hb}")
    differ = over = largest = 0
    for pa, pb in zip(a, b):
        if pa != pb:
            differ += 1
            d = max(abs(x - y) for x, y in zip(pa, pb))
            largest = max(largest, d)
            over += d > threshold
    drawn_a = sum(p != a[0] for p in a)
    drawn_b = sum(p != b[0] for p in b)
    total = wa * ha
    print(f"{wa}x{ha}: {differ} of {total} pixels differ ({100.0 * differ / total:.2f}%), "
          f"{over} by more than {threshold} ({100.0 * over / total:.2f}%), largest channel difference {largest}; "
          f"non-background pixels {drawn_a} / {drawn_b}")


if __name__ == "__main__":
    main()
