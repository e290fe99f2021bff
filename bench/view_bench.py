#!/usr/bin/env python3
"""view_bench.py QCS SCENE: qcs view's latency with a scripted client
(make bench). After each of N camera changes (an orbit step) and after a
save of the file: the time to the first (coarse) frame and to the full
frame. Loopback only."""
import http.client, math, os, re, shutil, statistics, subprocess, sys, tempfile, time

qcs, src = sys.argv[1], sys.argv[2]
work = tempfile.mkdtemp(prefix="qcs-viewbench-")
scene = os.path.join(work, os.path.basename(src))
shutil.copy(src, scene)
p = subprocess.Popen([qcs, "view", "--threads", "2", scene], stdout=subprocess.PIPE,
                     stderr=subprocess.DEVNULL, text=True)
url = None
for _ in range(20):
    m = re.search(r"http://([\d.]+):(\d+)/\?t=(\w+)", p.stdout.readline())
    if m: url = m; break
host, port, tok = url.group(1), int(url.group(2)), url.group(3)
conn = http.client.HTTPConnection(host, port, timeout=10)
def get(path):
    conn.request("GET", path)
    r = conn.getresponse(); body = r.read()
    return r.status, r.getheader("X-Step"), body
def ladder(q):
    t0 = time.perf_counter(); first = None; step = 16
    while step > 1:
        st, s, _ = get("/frame?t=%s&%s&step=%d" % (tok, q, step))
        if st != 200: continue
        step = int(s)
        if first is None: first = time.perf_counter() - t0
    return first, time.perf_counter() - t0
ladder("own=1")
firsts, fulls = [], []
for i in range(20):
    a = 0.05 * (i + 1)
    eye = (2.25 + 5.4 * math.sin(a), 3.2, -0.4 + 5.4 * math.cos(a))
    f, F = ladder("eye=%r,%r,%r&at=2.25,0.5,-0.4&up=0,1,0&fov=35" % eye)
    firsts.append(f); fulls.append(F)
print("qcs view, %s, 600x380 on 2 threads, 20 camera changes: first frame median %.1f ms (max %.1f), "
      "full frame median %.0f ms (max %.0f)" % (os.path.basename(src), 1e3 * statistics.median(firsts),
      1e3 * max(firsts), 1e3 * statistics.median(fulls), 1e3 * max(fulls)))
# a save: time from the rename to the first and the full frame of the new version
get("/state?t=%s" % tok)
conn.request("GET", "/state?t=%s" % tok); import json; v0 = json.loads(conn.getresponse().read())["version"]
orig = open(scene).read()
text = orig.replace("param r = 0.07 in", "param r = 0.08 in")
if text == orig:
    sys.exit("view_bench.py: the edit of %s matched nothing" % scene)
t0 = time.perf_counter()
open(scene + ".tmp", "w").write(text); os.rename(scene + ".tmp", scene)
first = full = None
while time.perf_counter() - t0 < 5:
    conn.request("GET", "/frame?t=%s&own=1&step=%d" % (tok, 16 if first is None else 2))
    r = conn.getresponse(); r.read()
    if r.status == 200 and int(r.getheader("X-Version")) > v0:
        if first is None: first = time.perf_counter() - t0
        if r.getheader("X-Step") == "1": full = time.perf_counter() - t0; break
    elif r.status == 200 and first is None: time.sleep(0.002)
print("qcs view, after a save (includes the 30 ms wait for the editor's rename dance): first frame %.0f ms, full frame %.0f ms"
      % (1e3 * (first or -1), 1e3 * (full or -1)))
p.send_signal(2); p.wait(10)
shutil.rmtree(work, ignore_errors=True)
