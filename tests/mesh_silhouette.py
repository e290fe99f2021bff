#!/usr/bin/env python3
"""mesh_silhouette.py A.png B.png MIN_IOU: the silhouettes of two pictures
(pixels away from each picture's own corner colour, the background)
compared by intersection over union; exit 0 when it is at least MIN_IOU.
Reads 8-bit RGB/RGBA PNGs with the standard library only (zlib)."""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise SystemExit('%s: not a PNG' % path)
    i, idat = 8, b''
    while i < len(data):
        n, kind = struct.unpack('>I4s', data[i:i + 8])
        chunk = data[i + 8:i + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', chunk[:10])
            if depth != 8 or ctype not in (2, 6):
                raise SystemExit('%s: not 8-bit RGB(A)' % path)
        elif kind == b'IDAT':
            idat += chunk
        i += 12 + n
    raw = zlib.decompress(idat)
    bpp = 3 if ctype == 2 else 4
    stride = w * bpp
    rows, prev, o = [], bytearray(stride), 0
    for _ in range(h):
        f = raw[o]
        o += 1
        line = bytearray(raw[o:o + stride])
        o += stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pr) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


def silhouette(path):
    w, h, bpp, rows = read_png(path)
    bg = rows[0][0:3]
    return w, h, [[sum(abs(rows[y][x * bpp + k] - bg[k]) for k in range(3)) > 24
                   for x in range(w)] for y in range(h)]


def main():
    w, h, a = silhouette(sys.argv[1])
    w2, h2, b = silhouette(sys.argv[2])
    if (w, h) != (w2, h2):
        print('sizes differ: %dx%d and %dx%d' % (w, h, w2, h2))
        return 1
    inter = sum(a[y][x] and b[y][x] for y in range(h) for x in range(w))
    union = sum(a[y][x] or b[y][x] for y in range(h) for x in range(w))
    iou = inter / union if union else 0.0
    print('silhouette IoU %.4f (%d pixels)' % (iou, union))
    return 0 if union > 0.05 * w * h and iou >= float(sys.argv[3]) else 1


if __name__ == '__main__':
    sys.exit(main())
