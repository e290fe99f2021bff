#!/usr/bin/env python3
"""parse_graphics.py MODE FILE: check that FILE holds well-formed terminal
graphics of MODE (kitty or sixel), as qcs --show --preview MODE writes them.
Prints nothing when they are; else one line saying what is wrong.

kitty: every APC escape (ESC _ G ... ESC \\) has key=value control data; the
first transmits and displays (a=T) an image of s x v pixels in format f (24:
RGB, 32: RGBA, 100: PNG); chunks carry m=1 but the last, m=0; the payload is
base64, chunk by chunk (each chunk is a whole base64 string, as kitty
decodes them on arrival), and decodes to exactly s * v * (f / 8) bytes (or
a PNG signature).

sixel: one DCS string (ESC P ... q ... ESC \\) per picture, whose body holds
only raster attributes, colour definitions (#n;2;r;g;b with percentages),
colour selections, repeats (!n), graphics carriage returns ($), new lines
(-) and sixel characters ('?' to '~'); the image it paints is as wide and as
high as its raster attributes say."""
import base64
import re
import sys


def fail(msg):
    print(msg)
    sys.exit(0)


def check_kitty(data):
    apcs = re.findall(rb"\x1b_G([^\x1b]*)\x1b\\", data)
    if not apcs:
        fail("kitty: no APC graphics escape")
    if data.count(b"\x1b_G") != len(apcs):
        fail("kitty: an APC escape is not terminated by ST")
    pictures = []
    cur = None
    for body in apcs:
        ctrl, _, payload = body.partition(b";")
        keys = {}
        for kv in ctrl.split(b","):
            if not kv:
                continue
            k, eq, v = kv.partition(b"=")
            if not eq or not re.fullmatch(rb"[a-zA-Z]", k):
                fail("kitty: bad control data %r" % ctrl[:60])
            keys[k.decode()] = v.decode()
        if cur is None:
            if keys.get("a") != "T":
                fail("kitty: the first chunk does not transmit and display (a=T)")
            f = int(keys.get("f", "32"))
            s, v = int(keys.get("s", "0")), int(keys.get("v", "0"))
            if f not in (24, 32, 100) or (f != 100 and (s <= 0 or v <= 0)):
                fail("kitty: bad format or size f=%d s=%d v=%d" % (f, s, v))
            cur = {"f": f, "s": s, "v": v, "payload": b""}
        if len(payload) % 4:
            fail("kitty: a chunk of %d base64 bytes (not a multiple of 4)" % len(payload))
        try:
            cur["payload"] += base64.b64decode(payload, validate=True)
        except Exception as e:  # noqa: BLE001
            fail("kitty: a chunk is not base64: %s" % e)
        if keys.get("m", "0") == "0":
            pictures.append(cur)
            cur = None
    if cur is not None:
        fail("kitty: the last chunk still says m=1")
    for p in pictures:
        raw = p["payload"]
        if p["f"] == 100:
            if not raw.startswith(b"\x89PNG\r\n\x1a\n"):
                fail("kitty: f=100 payload is not a PNG")
        elif len(raw) != p["s"] * p["v"] * p["f"] // 8:
            fail("kitty: payload of %d bytes for %dx%d pixels at f=%d"
                 % (len(raw), p["s"], p["v"], p["f"]))


def check_sixel(data):
    dcs = re.findall(rb"\x1bP([0-9;]*)q([^\x1b]*)\x1b\\", data)
    if not dcs:
        fail("sixel: no DCS sixel string")
    if data.count(b"\x1bP") != len(dcs):
        fail("sixel: a DCS string is not a terminated sixel string")
    for _, body in dcs:
        i, n = 0, len(body)
        width = height_rows = x = 0
        raster = None
        colours = set()
        while i < n:
            c = body[i:i + 1]
            if c == b'"':
                m = re.match(rb'"(\d+);(\d+);(\d+);(\d+)', body[i:])
                if not m:
                    fail("sixel: bad raster attributes")
                raster = (int(m.group(3)), int(m.group(4)))
                i += m.end()
            elif c == b"#":
                m = re.match(rb"#(\d+)(?:;(\d+);(\d+);(\d+);(\d+))?", body[i:])
                if not m:
                    fail("sixel: bad colour introducer")
                if m.group(2) is not None:
                    if m.group(2) not in (b"1", b"2"):
                        fail("sixel: unknown colour space %r" % m.group(2))
                    if m.group(2) == b"2" and any(int(m.group(k)) > 100 for k in (3, 4, 5)):
                        fail("sixel: an RGB percentage above 100")
                    colours.add(int(m.group(1)))
                elif int(m.group(1)) not in colours:
                    fail("sixel: colour %s selected before it is defined" % m.group(1).decode())
                i += m.end()
            elif c == b"!":
                m = re.match(rb"!(\d+)([?-~])", body[i:])
                if not m:
                    fail("sixel: bad repeat")
                x += int(m.group(1))
                i += m.end()
            elif c == b"$":
                width = max(width, x)
                x = 0
                i += 1
            elif c == b"-":
                width = max(width, x)
                x = 0
                height_rows += 1
                i += 1
            elif b"?" <= c <= b"~":
                x += 1
                i += 1
            elif c in (b"\r", b"\n"):
                i += 1
            else:
                fail("sixel: unexpected byte %r at %d" % (c, i))
        width = max(width, x)
        if body.rstrip(b"\r\n").endswith(b"-"):
            height_rows -= 1
        height = 6 * (height_rows + 1)
        if raster is None:
            fail("sixel: no raster attributes")
        if width != raster[0]:
            fail("sixel: painted %d columns, raster says %d" % (width, raster[0]))
        if not (raster[1] <= height < raster[1] + 6):
            fail("sixel: painted %d rows, raster says %d" % (height, raster[1]))


def main():
    mode, path = sys.argv[1], sys.argv[2]
    data = open(path, "rb").read()
    if mode == "kitty":
        check_kitty(data)
    elif mode == "sixel":
        check_sixel(data)
    else:
        fail("unknown mode %s" % mode)


main()
