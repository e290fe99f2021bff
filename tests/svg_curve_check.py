#!/usr/bin/env python3
"""svg_curve_check.py PNG SVG CLASS: check a browser's screenshot of an SVG
plot (drawn 1:1 at the page's top-left) against the SVG's own geometry, a
robust check instead of a byte comparison of anti-aliased text:
  - the PNG is not blank (many non-white pixels);
  - along the polyline of class CLASS, nearly every vertex has a dark pixel
    within 2 px (the curve is drawn where the data says);
  - the curve mirrored about the plot's middle is white (not drawn upside
    down), checked where it is far from the true curve;
  - every red marker circle (fill #d62728) has red pixels at its centre.
Prints one line "ok" or "bad: why" and exits 0 or 1. Decodes 8-bit
non-interlaced RGB/RGBA PNG (what Chromium writes) with zlib only."""
import re, struct, sys, zlib

def read_png(path):
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
    pos, idat, w = 8, b'', 0
    while pos < len(data):
        n, typ = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if typ == b'IHDR':
            w, h, depth, ctype, _, _, inter = struct.unpack('>IIBBBBB', body)
            assert depth == 8 and ctype in (2, 6) and inter == 0, 'PNG kind'
            bpp = 3 if ctype == 2 else 4
        elif typ == b'IDAT':
            idat += body
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev, i = [], bytearray(stride), 0
    for _ in range(h):
        f, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pr) & 255
        rows.append(line)
        prev = line
    return w, h, lambda x, y: tuple(rows[y][x * bpp:x * bpp + 3])

def main():
    png, svg, cls = sys.argv[1:4]
    w, h, px = read_png(png)
    text = open(svg).read()
    m = re.search(r'<polyline class="%s"[^>]*points="([^"]*)"' % re.escape(cls), text)
    if not m:
        return 'no polyline of class ' + cls
    pts = [tuple(map(float, p.split(','))) for p in m.group(1).split()]
    inside = lambda x, y: 0 <= x < w and 0 <= y < h
    dark = lambda c: sum(c) < 3 * 110
    nonwhite = sum(1 for y in range(0, h, 2) for x in range(0, w, 2)
                   if sum(px(x, y)) < 3 * 240)
    if nonwhite < 0.01 * (w // 2) * (h // 2):
        return 'blank: %d non-white sampled pixels' % nonwhite
    def near_dark(x, y, r):
        return any(inside(x + dx, y + dy) and dark(px(x + dx, y + dy))
                   for dx in range(-r, r + 1) for dy in range(-r, r + 1))
    hit = sum(1 for x, y in pts if near_dark(round(x), round(y), 2))
    if hit < 0.95 * len(pts):
        return 'curve: only %d of %d vertices have a dark pixel nearby' % (hit, len(pts))
    ys = [y for _, y in pts]
    mid = (min(ys) + max(ys)) / 2
    far = [(x, 2 * mid - y) for x, y in pts if abs(2 * mid - 2 * y) > 25]
    wrong = sum(1 for x, y in far if near_dark(round(x), round(y), 1))
    if not far or wrong > 0.1 * len(far):
        return 'mirrored curve drawn: %d of %d points dark' % (wrong, len(far))
    for cx, cy in re.findall(r'<circle cx="([-\d.]+)" cy="([-\d.]+)" r="[\d.]+" fill="#d62728"', text):
        r, g, b = px(round(float(cx)), round(float(cy)))
        if not (r > 150 and g < 110 and b < 110):
            return 'marker at (%s, %s) is not red: %s' % (cx, cy, (r, g, b))
    return None

if __name__ == '__main__':
    why = main()
    print('ok' if why is None else 'bad: ' + why)
    sys.exit(0 if why is None else 1)
