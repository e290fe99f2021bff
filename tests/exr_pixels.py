#!/usr/bin/env python3
"""exr_pixels.py FILE CHANNEL X,Y...: print CHANNEL's value at each pixel
(full-picture coordinates), read by this small reader of its own (scanline
EXR, NONE or ZIP compression, half or float), independent of OpenEXR and
of qcs: tests/suite-farm.sh uses it to check alpha."""
import struct, sys, zlib

def read(path):
    b = open(path, 'rb').read()
    assert struct.unpack_from('<I', b, 0)[0] == 20000630, 'not an EXR'
    p, attrs = 8, {}
    while b[p] != 0:
        e = b.index(0, p); name = b[p:e].decode(); p = e + 1
        e = b.index(0, p); typ = b[p:e].decode(); p = e + 1
        n = struct.unpack_from('<i', b, p)[0]; p += 4
        attrs[name] = (typ, b[p:p + n]); p += n
    p += 1
    chans, q, cl = [], 0, attrs['channels'][1]
    while cl[q] != 0:
        e = cl.index(0, q); name = cl[q:e].decode(); q = e + 1
        pt = struct.unpack_from('<i', cl, q)[0]; q += 16
        chans.append((name, pt))
    x0, y0, x1, y1 = struct.unpack('<4i', attrs['dataWindow'][1])
    comp = attrs['compression'][1][0]
    lines = {0: 1, 3: 16, 2: 1}[comp]
    w, h = x1 - x0 + 1, y1 - y0 + 1
    nchunks = (h + lines - 1) // lines
    offs = struct.unpack_from('<%dQ' % nchunks, b, p)
    px = {}
    for off in offs:
        y, size = struct.unpack_from('<ii', b, off)
        data = b[off + 8: off + 8 + size]
        nl = min(lines, y1 - y + 1)
        raw = sum(w * (2 if pt == 1 else 4) for _, pt in chans) * nl
        if comp and size != raw:
            t = bytearray(zlib.decompress(data))
            for i in range(1, len(t)):
                t[i] = (t[i - 1] + t[i] - 128) & 255
            half = (len(t) + 1) // 2
            out = bytearray(len(t))
            out[0::2] = t[:half]; out[1::2] = t[half:]
            data = bytes(out)
        o = 0
        for row in range(nl):
            for name, pt in chans:
                fmt, sz = ('<e', 2) if pt == 1 else ('<f', 4)
                for x in range(w):
                    px[(name, x0 + x, y + row)] = struct.unpack_from(fmt, data, o)[0]
                    o += sz
    return px

px = read(sys.argv[1])
for xy in sys.argv[3:]:
    x, y = map(int, xy.split(','))
    print(px[(sys.argv[2], x, y)])
