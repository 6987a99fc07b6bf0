#!/usr/bin/env bash
# Motion-capture markers through the tools (docs/formats.md sections 1-3 and 6): the bundled
# robot with two markers; softrne-sim writes their base-frame positions; those, turned into a
# capture frame (rotation 0.7 rad, shift 1.2 / 0.3 / -0.5 m) with 1 mm noise, are the only
# measurements softrne-fit gets, from a starting robot with stiffness and damping off by 1.5
# and 0.7. Its report must hold the capture frame within 5 standard errors of the truth and
# marker errors down to the noise (mean distance 1.60 mm for 1 mm per axis).
#
#   test_markers.sh <softrne-sim> <softrne-fit> <python3> <examples/data/arm-a-1>
set -u
if [[ $# -ne 4 ]]; then
  echo "usage: $0 <softrne-sim> <softrne-fit> <python3> <examples/data/arm-a-1>" >&2
  exit 2
fi
sim=$1 fit=$2 py=$3 data=$4
source "$(dirname "$0")/common.sh"
make_scratch softrne-markers

"$py" - "$data/robot.json" "$tmp" <<'PY' || fail "writing the robot files"
import json, sys
r = json.load(open(sys.argv[1]))
r["markers"] = [{"name": "tip", "segment": r["segments"][-1]["name"], "offset": [0, 0, 0.02]},
                {"name": "mid", "segment": r["segments"][3]["name"], "offset": [0.03, 0, 0]}]
json.dump(r, open(sys.argv[2] + "/robot.json", "w"), indent=1)
for s in r["segments"]:
    if s["type"] == "cc_joint":
        s["stiffness"] = [1.5 * k for k in s["stiffness"]]
        s["damping"] = [0.7 * d for d in s["damping"]]
json.dump(r, open(sys.argv[2] + "/start.json", "w"), indent=1)
PY
if "$sim" --robot "$tmp/robot.json" --pressures "$data/train.csv" --out "$tmp/sim.csv" --quiet >/dev/null \
  2>"$tmp/stderr.txt" </dev/null && head -1 "$tmp/sim.csv" | grep -q ",tip_x,tip_y,tip_z,mid_x,mid_y,mid_z$"; then
  echo "ok   softrne-sim writes the markers' positions"
else
  fail "softrne-sim with markers: $(cat "$tmp/stderr.txt") $(head -1 "$tmp/sim.csv" 2>/dev/null)"
fi
"$py" - "$data/train.csv" "$tmp/sim.csv" "$tmp/markers.csv" <<'PY' || fail "writing the marker data"
import math, random, sys
def read(p):
    rows = [l for l in open(p).read().splitlines() if not l.startswith("#")]
    return rows[0].split(","), [[float(x) for x in l.split(",")] for l in rows[1:]]
hp, ap = read(sys.argv[1])
hs, as_ = read(sys.argv[2])
th, ax = 0.7, [0.2, -1.0, 0.4]
n = math.sqrt(sum(a * a for a in ax)); ax = [a / n for a in ax]
K = [[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]]
KK = [[sum(K[i][k] * K[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
R = [[(i == j) + math.sin(th) * K[i][j] + (1 - math.cos(th)) * KK[i][j] for j in range(3)] for i in range(3)]
t = [1.2, 0.3, -0.5]
random.seed(3)
keep = [i for i, h in enumerate(hp) if h == "t" or h.startswith("p")]
with open(sys.argv[3], "w") as f:
    f.write(",".join([hp[i] for i in keep] + [m + a for m in ("tip", "mid") for a in ("_x", "_y", "_z")]) + "\n")
    for rp, rs in zip(ap, as_):
        cells = [rp[i] for i in keep]
        for m in ("tip", "mid"):
            x = rs[hs.index(m + "_x"):hs.index(m + "_x") + 3]
            cells += [sum(R[i][k] * x[k] for k in range(3)) + t[i] + random.gauss(0, 1e-3) for i in range(3)]
        f.write(",".join(repr(c) for c in cells) + "\n")
PY
if "$fit" --robot "$tmp/start.json" --data "$tmp/markers.csv" --out "$tmp/fitted.json" --report "$tmp/report.json" \
  --quiet >"$tmp/stdout.txt" 2>"$tmp/stderr.txt" </dev/null; then
  echo "ok   softrne-fit from markers alone"
else
  fail "softrne-fit from markers alone: $(cat "$tmp/stderr.txt")"
fi
"$py" - "$tmp/report.json" <<'PY' || fail "the report of the fit from markers"
import json, math, sys
r = json.load(open(sys.argv[1]))
assert not r["capture_frames"]["per_recording"]
f = r["capture_frames"]["frames"][0]
R, t, se = f["rotation"], f["translation"], f["std_errors"]
th, ax = 0.7, [0.2, -1.0, 0.4]
n = math.sqrt(sum(a * a for a in ax)); ax = [a / n for a in ax]
# The fitted rotation's angle and axis (from its trace and skew part) against the truth.
angle = math.acos(max(-1.0, min(1.0, (R[0][0] + R[1][1] + R[2][2] - 1) / 2)))
axis = [R[2][1] - R[1][2], R[0][2] - R[2][0], R[1][0] - R[0][1]]
s = math.sqrt(sum(a * a for a in axis)); axis = [a / s for a in axis]
rot_err = [angle * a - th * b for a, b in zip(axis, ax)]  # small: rotation vectors subtract
for i in range(3):
    assert abs(rot_err[i]) < 5 * se[i] + 1e-9, (i, rot_err, se)
    assert abs(t[i] - [1.2, 0.3, -0.5][i]) < 5 * se[3 + i], (i, t, se)
m = r["markers"]
assert m["unit"] == "mm"
assert r["train"]["after"] is None  # no angles were given
before, after = m["train"]["before"]["mean"], m["train"]["after"]["mean"]
assert after < before and abs(after - 1.60) < 0.15, (before, after)
print(f"ok   report: capture frame within 5 std errors; marker mean error {before:.2f} -> {after:.2f} mm")
PY
finish
