#!/usr/bin/env python3
"""Latency of `pneumo serve` as a user feels it (issue 22, item 5), medians over repetitions.

Starts `pneumo serve` on a scene (the demo's medium phantom by default) at a preset, then measures
over HTTP, as the page asks:
  - load: process start to the first answer, and to the first equilibrium;
  - camera: a new laparoscope view (the aim turned by a few degrees), N times;
  - exterior: a new body view, N times;
  - pressure: a change of 2 mmHg, from the request to the first view of a new shape (at the half
    size the page asks for while the solver runs) and to the converged equilibrium (alternating up
    and down, N times).
Records the load average and the CPU other processes used meanwhile (from /proc/stat less this
run's own), since this machine is shared. Writes a Markdown table (stdout, or --markdown FILE) and
JSON (--json FILE).

Usage: bench/serve_latency.py [--pneumo build/pneumo] [--scene scenes/phantom_ports_flythrough.json]
                              [--preset preview] [--repeats 5] [--json F] [--markdown F]
"""
import argparse, json, os, re, statistics, subprocess, sys, time, urllib.request

ap = argparse.ArgumentParser()
ap.add_argument("--pneumo", default="build/pneumo")
ap.add_argument("--scene", default="scenes/phantom_ports_flythrough.json")
ap.add_argument("--preset", default="preview")
ap.add_argument("--repeats", type=int, default=5)
ap.add_argument("--json")
ap.add_argument("--markdown")
a = ap.parse_args()


def cpu_times():
    with open("/proc/stat") as f:
        v = [int(x) for x in f.readline().split()[1:]]
    return sum(v) - v[3] - v[4], sum(v)   # busy, total (jiffies)


def own_jiffies(pid):
    with open(f"/proc/{pid}/stat") as f:
        s = f.read().rsplit(")", 1)[1].split()
    return int(s[11]) + int(s[12]) + int(s[13]) + int(s[14])


scene = json.load(open(a.scene))
base = os.path.dirname(os.path.abspath(a.scene))
for k in ("ct", "labels", "label_names"):
    if k in scene.get("inputs", {}):
        scene["inputs"][k] = os.path.normpath(os.path.join(base, scene["inputs"][k]))
scene["preset"] = a.preset
tmp = f"/tmp/pneumo_serve_bench_{os.getpid()}.json"
json.dump(scene, open(tmp, "w"))
port = scene["render"]["ports"][0]
target = port.get("target_label", 5)

load0 = os.getloadavg()
busy0, total0 = cpu_times()
t_start = time.time()
server = subprocess.Popen([a.pneumo, "-q", "serve", tmp, "--port", "0", "--out", f"/tmp/pneumo_serve_bench_out_{os.getpid()}"],
                          stdout=subprocess.PIPE, text=True)
url = "http://127.0.0.1:%s" % re.search(r":(\d+)/", server.stdout.readline()).group(1)


def get(path):
    with urllib.request.urlopen(url + path, timeout=600) as r:
        return r.read()


def post(path, body):
    req = urllib.request.Request(url + path, json.dumps(body).encode(), {"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=600) as r:
        return json.loads(r.read())


def status():
    return json.loads(get("/api/status"))


def wait(cond, seconds=900):
    end = time.time() + seconds
    while time.time() < end:
        s = status()
        if cond(s):
            return s
        time.sleep(0.02)
    sys.exit("timed out")


rows = {}
try:
    t_up = time.time() - t_start
    s = wait(lambda s: not s["solving"] and s.get("generation", 0) >= 1)
    rows["load: first answer, s"] = [t_up]
    rows["load: first equilibrium, s"] = [time.time() - t_start]
    sx, sy, sz = port["skin_point_mm"]
    def timed(path_of):   # seconds per request, a new path each time
        out = []
        for k in range(a.repeats):
            t = time.time()
            get(path_of(k))
            out.append(time.time() - t)
        return out
    rows["camera change to new view (480×360), s"] = timed(
        lambda k: f"/api/scope.png?sx={sx}&sy={sy}&sz={sz}&label={target}&ins=45&obl=30&yaw={3 * (k + 1)}&w=480&h=360")
    rows["body view (480×360), s"] = timed(
        lambda k: f"/api/exterior.png?side={'anterior' if k % 2 == 0 else 'left'}&w=480&h=360")
    first, conv = [], []
    p = s["pressure_mmhg"]
    for k in range(a.repeats):
        shape = status()["shape"]
        p = p - 2 if k % 2 == 0 else p + 2
        t = time.time()
        g = post("/api/inflate", {"pressure_mmhg": p})["generation"]
        wait(lambda s: s["shape"] > shape)
        # While the solver runs the page asks for the view at half size (host/serve/page/app.js).
        get(f"/api/scope.png?sx={sx}&sy={sy}&sz={sz}&label={target}&ins=45&obl=30&w=240&h=180")
        first.append(time.time() - t)
        wait(lambda s: not s["solving"] and s.get("generation") == g)
        conv.append(time.time() - t)
    rows["pressure ±2 mmHg to the first updated view (240×180, as the page asks while solving), s"] = first
    rows["pressure ±2 mmHg to the equilibrium, s"] = conv
    s = status()
finally:
    own = own_jiffies(server.pid) if server.poll() is None else 0
    server.terminate()
    server.wait(timeout=60)
    os.remove(tmp)
busy1, total1 = cpu_times()
ncpu = os.cpu_count()
wall = time.time() - t_start
other_cores = max(0.0, ((busy1 - busy0) - own) / max(1, (total1 - total0)) * ncpu)
doc = {"scene": a.scene, "preset": a.preset, "repeats": a.repeats, "tetrahedra": s.get("tetrahedra"),
       "renderer": s.get("renderer", {}).get("gl_renderer"), "load_average_start": load0,
       "load_average_end": os.getloadavg(), "other_cores": other_cores, "cpus": ncpu, "wall_s": wall,
       "rows": {k: {"median": statistics.median(v), "min": min(v), "max": max(v), "n": len(v)} for k, v in rows.items()}}
md = [f"`pneumo serve {a.scene}` at `{a.preset}` ({doc['tetrahedra']} tetrahedra, {doc['renderer']}), "
      f"{a.repeats} repetitions; load average {load0[0]:.2f} at the start, {doc['load_average_end'][0]:.2f} at the end; "
      f"other processes used {other_cores:.1f} of {ncpu} cores.", "",
      "| what | median | min–max |", "|---|---|---|"]
for k, v in doc["rows"].items():
    md.append(f"| {k} | {v['median']:.2f} | {v['min']:.2f}–{v['max']:.2f} |")
text = "\n".join(md) + "\n"
print(text)
if a.markdown:
    open(a.markdown, "w").write(text)
if a.json:
    json.dump(doc, open(a.json, "w"), indent=2)
