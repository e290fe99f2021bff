#!/usr/bin/env python3
"""mesh_read.py FILE: reads a binary PLY, a 3MF or a binary STL written by
qcs with the standard library only (struct, zipfile, xml) and prints
'V T parts=P closed=0|1 colours=N', closed meaning every directed edge
once with its reverse once (an independent edge count), P the connected
components of triangles sharing a vertex (an STL's vertices are welded by
their exact coordinates; it has no colours)."""
import collections
import struct
import sys
import xml.etree.ElementTree as ET
import zipfile


def read_ply(path):
    data = open(path, 'rb').read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    head = data[:end].decode().split('\n')
    assert head[0] == 'ply' and head[1] == 'format binary_little_endian 1.0'
    nv = int([l for l in head if l.startswith('element vertex')][0].split()[2])
    nt = int([l for l in head if l.startswith('element face')][0].split()[2])
    o, cols, tris = end, set(), []
    for _ in range(nv):
        struct.unpack_from('<3f', data, o)
        cols.add(data[o + 12:o + 15])
        o += 15
    for _ in range(nt):
        assert data[o] == 3
        tris.append(struct.unpack_from('<3i', data, o + 1))
        o += 13
    assert o == len(data), 'trailing bytes'
    return nv, tris, len(cols)


def read_3mf(path):
    z = zipfile.ZipFile(path)
    assert '[Content_Types].xml' in z.namelist() and '_rels/.rels' in z.namelist()
    ns = {'m': 'http://schemas.microsoft.com/3dmanufacturing/core/2015/02'}
    root = ET.fromstring(z.read('3D/3dmodel.model'))
    nv = len(root.findall('.//m:vertex', ns))
    tris = [(int(t.get('v1')), int(t.get('v2')), int(t.get('v3')))
            for t in root.findall('.//m:triangle', ns)]
    cols = len(root.findall('.//m:base', ns))
    return nv, tris, cols


def read_stl(path):
    data = open(path, 'rb').read()
    nt = struct.unpack_from('<I', data, 80)[0]
    assert len(data) == 84 + 50 * nt, 'size'
    index, tris = {}, []
    for i in range(nt):
        o = 84 + 50 * i + 12
        tris.append(tuple(index.setdefault(data[o + 12 * k:o + 12 * k + 12], len(index))
                          for k in range(3)))
    return len(index), tris, 0


def parts(nv, tris):
    up = list(range(nv))

    def find(x):
        while up[x] != x:
            up[x] = up[up[x]]
            x = up[x]
        return x
    for t in tris:
        for k in (1, 2):
            up[find(t[k])] = find(t[0])
    return len({find(t[0]) for t in tris})


def main():
    path = sys.argv[1]
    nv, tris, cols = (read_3mf(path) if path.endswith('.3mf') else
                      read_stl(path) if path.endswith('.stl') else read_ply(path))
    edges = collections.Counter()
    for t in tris:
        for k in range(3):
            edges[(t[k], t[(k + 1) % 3])] += 1
    closed = all(c == 1 and edges.get((b, a)) == 1 for (a, b), c in edges.items())
    print('%d %d parts=%d closed=%d colours=%d' % (nv, len(tris), parts(nv, tris),
                                                 int(closed), cols))


if __name__ == '__main__':
    main()
