#!/usr/bin/env python3
"""pty_term.py: qcs's REPL on a pseudo-terminal that plays a terminal.

    pty_term.py QCS CASE

CASE says what the terminal answers to DA1 (ESC [ c) at start-up and
what is checked:
  sixel     answers "ESC [ ? 62 ; 4 ; 22 c": a scene is drawn in sixels
  nosixel   answers "ESC [ ? 62 ; 22 c": symbols in 24-bit colour
  silent    does not answer: symbols, and the prompt comes within 1 s
  redirect  standard output is a file: the file holds the values only
            (no prompt, no escape code); the prompt is on the terminal
Prints "ok pty-CASE" or "FAIL pty-CASE: why" and exits 0 or 1.
"""
import os, pty, select, signal, sys, tempfile, time

qcs, case = sys.argv[1], sys.argv[2]
name = "pty-" + case
ESC = b"\x1b"


def fail(why):
    print("FAIL %s: %s" % (name, why))
    sys.exit(1)


env = {k: v for k, v in os.environ.items()
       if k not in ("TMUX", "STY", "TERM_PROGRAM", "KITTY_WINDOW_ID",
                    "VTE_VERSION", "COLORTERM", "WT_SESSION", "LC_TERMINAL")}
env["TERM"] = "xterm-256color"
home = tempfile.mkdtemp()
env["HOME"] = home
outfile = os.path.join(home, "out.txt")

pid, fd = pty.fork()
if pid == 0:
    if case == "redirect":
        f = os.open(outfile, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(f, 1)
    os.execve(qcs, [qcs], env)

buf = b""
answered = False
t0 = time.time()


def pump(until, limit=20.0):
    """Read the pty until until(buf) or limit seconds; answer DA1 once."""
    global buf, answered
    end = time.time() + limit
    while time.time() < end:
        if until(buf):
            return True
        r, _, _ = select.select([fd], [], [], 0.05)
        if not r:
            continue
        try:
            k = os.read(fd, 65536)
        except OSError:
            return until(buf)
        if not k:
            return until(buf)
        buf += k
        if not answered and ESC + b"[c" in buf:
            answered = True
            if case == "sixel":
                os.write(fd, ESC + b"[?62;4;22c")
            elif case in ("nosixel", "redirect"):
                os.write(fd, ESC + b"[?62;22c")
    return until(buf)


try:
    if not pump(lambda b: b"qcs> " in b):
        fail("no prompt; got %r" % buf[-200:])
    t_prompt = time.time() - t0
    if case != "redirect" and not answered:
        fail("the terminal was not asked (no ESC [ c before the prompt)")
    mark = len(buf)
    os.write(fd, b"Rounded 0.1 UnitCube\r")
    pump(lambda b: b.count(b"qcs> ", mark) >= 1, 30.0)
    got = buf[mark:]
    os.write(fd, b":quit\r")
    pump(lambda b: False, 1.0)
finally:
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    os.waitpid(pid, 0)

sixel = ESC + b"P" in got and ESC + b"\\" in got
truecolour = ESC + b"[38;2;" in got or ESC + b"[48;2;" in got
if case == "sixel":
    if not sixel:
        fail("no sixel picture after a DA1 answer with 4; got %r" % got[:200])
elif case in ("nosixel", "silent"):
    if sixel:
        fail("sixels drawn for a terminal that did not claim them")
    if not truecolour:
        fail("no symbols picture; got %r" % got[:200])
    # a sanitizer build starts slower; the question waits 0.15 s at most
    slow = 5.0 if ("QCS_TSAN" in os.environ or "ASAN_OPTIONS" in os.environ) else 1.0
    if case == "silent" and t_prompt > slow:
        fail("the prompt took %.2f s behind an unanswered question" % t_prompt)
elif case == "redirect":
    data = open(outfile, "rb").read()
    if ESC in data or b"qcs>" in data:
        fail("the file got the prompt or escape codes: %r" % data[:200])
    if b"Rounded 0.1" not in data:
        fail("the file lacks the value: %r" % data[:200])
    if b"qcs> " not in buf:
        fail("no prompt on the terminal")
print("ok " + name)
