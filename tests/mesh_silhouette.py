#!/usr/bin/env python3
"""mesh_silhouette.py A.png B.png MIN_IOU: the silhouettes of two pictures
(pixels away from each picture's own corner colour, the background)
compared by intersection over union; exit 0 when it is at least MIN_IOU.
Reads 8-bit RGB/RGBA PNGs with svg_curve_check.read_png (zlib only)."""
import sys

from svg_curve_check import read_png  # 8-bit RGB(A) PNG, zlib only


def silhouette(path):
    w, h, px = read_png(path)
    bg = px(0, 0)
    return w, h, [[sum(abs(px(x, y)[k] - bg[k]) for k in range(3)) > 24
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
