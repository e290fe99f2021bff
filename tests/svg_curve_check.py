#!/usr/bin/env python3
"""svg_curve_check.py PNG SVG CLASS...: check a browser's screenshot of an
SVG plot (drawn 1:1 at the page's top-left) against the SVG's own geometry,
a robust check instead of a byte comparison of anti-aliased text:
  - the PNG is not blank (many non-white pixels);
  - along each polyline of a class CLASS, nearly every vertex has a pixel
    of the line's stroke colour within 2 px (the curve is drawn where the
    data says), and the curve mirrored about its middle height is not drawn
    there (not upside down), checked where it is far from the true curve;
  - every red marker circle (fill #d62728) is red at its centre;
  - every bar of the plots' rows (rect of class segment or soft-interval,
    at least 8 px wide) shows its fill colour (blended with white by its
    fill-opacity) inside its left end;
  - every tick mark of the axes (a black line 5 px long) is drawn (a 1 px
    line on a pixel boundary is two grey pixels);
  - an embedded picture (<image href=NAME>, a PNG beside the SVG) appears
    pixel for pixel where the SVG puts it (--image).
Prints one line "ok" or "bad: why" and exits 0 or 1. Decodes 8-bit
non-interlaced RGB/RGBA PNG (what Chromium and qcs write) with zlib only."""
import os, re, struct, sys, zlib

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

def colour(s):
    if s == 'black': return (0, 0, 0)
    if s == 'white': return (255, 255, 255)
    m = re.fullmatch(r'#([0-9a-fA-F]{6})', s)
    if m: return tuple(int(m.group(1)[i:i + 2], 16) for i in (0, 2, 4))
    m = re.fullmatch(r'rgb\((\d+),(\d+),(\d+)\)', s)
    if m: return tuple(int(g) for g in m.groups())
    return None

def attr(tag, name):
    m = re.search(r'\s%s="([^"]*)"' % name, tag)
    return m.group(1) if m else None

def main():
    args = sys.argv[1:]
    image = '--image' in args
    args = [a for a in args if a != '--image']
    png, svg, classes = args[0], args[1], args[2:]
    w, h, px = read_png(png)
    text = open(svg).read()
    inside = lambda x, y: 0 <= x < w and 0 <= y < h
    near = lambda c, s, tol: max(abs(c[i] - s[i]) for i in range(3)) <= tol
    nonwhite = sum(1 for y in range(0, h, 2) for x in range(0, w, 2)
                   if sum(px(x, y)) < 3 * 240)
    if nonwhite < 0.01 * (w // 2) * (h // 2):
        return 'blank: %d non-white sampled pixels' % nonwhite
    def near_col(x, y, r, s):
        return any(inside(x + dx, y + dy) and near(px(x + dx, y + dy), s, 80)
                   for dx in range(-r, r + 1) for dy in range(-r, r + 1))
    for cls in classes:
        tags = re.findall(r'<polyline class="%s"[^>]*>' % re.escape(cls), text)
        if not tags:
            return 'no polyline of class ' + cls
        for tag in tags:
            s = colour(attr(tag, 'stroke') or 'black')
            pts = [tuple(map(float, p.split(','))) for p in attr(tag, 'points').split()]
            hit = sum(1 for x, y in pts if near_col(round(x), round(y), 2, s))
            if hit < 0.95 * len(pts):
                return '%s: only %d of %d vertices have a pixel of its colour nearby' % (cls, hit, len(pts))
            ys = [y for _, y in pts]
            mid = (min(ys) + max(ys)) / 2
            far = [(x, 2 * mid - y) for x, y in pts if abs(2 * mid - 2 * y) > 25]
            wrong = sum(1 for x, y in far if near_col(round(x), round(y), 1, s))
            if len(far) >= 5 and wrong > 0.1 * len(far):
                return '%s: mirrored curve drawn: %d of %d points' % (cls, wrong, len(far))
    for tag in re.findall(r'<circle [^>]*fill="#d62728"[^>]*>', text):
        cx, cy = float(attr(tag, 'cx')), float(attr(tag, 'cy'))
        if not inside(round(cx), round(cy)):
            continue
        r, g, b = px(round(cx), round(cy))
        if not (r > 150 and g < 110 and b < 110):
            return 'marker at (%s, %s) is not red: %s' % (cx, cy, (r, g, b))
    bars = 0
    for tag in re.findall(r'<rect class="(?:segment|soft-interval)"[^>]*>', text):
        x, y = float(attr(tag, 'x')), float(attr(tag, 'y'))
        bw, bh = float(attr(tag, 'width')), float(attr(tag, 'height'))
        if bw < 8 or bh < 8:
            continue
        f = colour(attr(tag, 'fill'))
        op = float(attr(tag, 'fill-opacity') or 1)
        want = tuple(op * f[i] + (1 - op) * 255 for i in range(3))
        got = px(round(x + 4), round(y + bh / 2))
        if not near(got, want, 40):
            return 'bar at (%g, %g) shows %s, not %s' % (x, y, got, tuple(round(v) for v in want))
        bars += 1
    ticks = re.findall(r'<line x1="([-\d.]+)" y1="([-\d.]+)" x2="([-\d.]+)" y2="([-\d.]+)" stroke="black"/>', text)
    for x1, y1, x2, y2 in ticks:
        x1, y1, x2, y2 = map(float, (x1, y1, x2, y2))
        mx, my = round((x1 + x2) / 2), round((y1 + y2) / 2)
        if not any(inside(mx + dx, my + dy) and max(px(mx + dx, my + dy)) < 200
                   for dx in (-1, 0, 1) for dy in (-1, 0, 1)):
            return 'tick at (%g, %g) not drawn' % (mx, my)
    if image:
        tag = re.search(r'<image [^>]*>', text)
        if not tag:
            return 'no <image>'
        tag = tag.group(0)
        ix, iy = round(float(attr(tag, 'x'))), round(float(attr(tag, 'y')))
        src = os.path.join(os.path.dirname(svg), attr(tag, 'href'))
        iw, ih, ipx = read_png(src)
        if (iw, ih) != (round(float(attr(tag, 'width'))), round(float(attr(tag, 'height')))):
            return 'the picture is %dx%d, the SVG says %sx%s' % (iw, ih, attr(tag, 'width'), attr(tag, 'height'))
        bad = total = 0
        for y in range(1, ih - 1, 3):
            for x in range(1, iw - 1, 3):
                if not inside(ix + x, iy + y):
                    return 'the picture falls outside the screenshot'
                total += 1
                if not near(px(ix + x, iy + y), ipx(x, y), 12):
                    bad += 1
        if bad > 0.01 * total:
            return 'the picture differs from %s at %d of %d sampled pixels' % (src, bad, total)
    return None

if __name__ == '__main__':
    why = main()
    print('ok' if why is None else 'bad: ' + why)
    sys.exit(0 if why is None else 1)
