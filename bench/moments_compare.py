#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""bench/moments_compare.py: the moment shadow map's comparisons at equal memory, from an
`umbra-bench accuracy` CSV (docs/moments.md quotes its output).

Per scene: CSSM's and the fixed-budget deep map's (3 nodes) 512^2 rows against the best moment
row holding at most their memory (5% slack: map sizes are whole texels); moments' build time
against the threshold map's at 512^2 (both build one ray per texel); every map row's render time
over the unshadowed frame; and the Pareto front over bytes per map texel (the CSV's
pareto_texel). Markdown on stdout.

Usage: bench/moments_compare.py [bench/results/accuracy/moments/accuracy.csv]
"""
import csv
import sys

MAPS = ("threshold", "cssm", "deep", "moments")


def load(path):
    with open(path, newline="") as f:
        return [r for r in csv.DictReader(f)]


def num(r, k):
    try:
        return float(r[k])
    except (KeyError, ValueError):
        return float("nan")


def find(rows, scene, tech, params):
    for r in rows:
        if r["scene"] == scene and r["technique"] == tech and r["params"] == params:
            return r
    return None


def best_moments(rows, scene, memory):
    cands = [r for r in rows if r["scene"] == scene and r["technique"] == "moments"
             and num(r, "memory_bytes") <= 1.05 * memory and num(r, "rmse") > 0]
    return min(cands, key=lambda r: num(r, "rmse")) if cands else None


def mib(b):
    return "%.2f MiB" % (b / 1048576.0)


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "bench/results/accuracy/moments/accuracy.csv"
    rows = load(path)
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    cssm_p = "map_size=512;taps=13;seed=1"
    deep_p = "map_size=512;epsilon=0.02;max_nodes=3;prefilter=1"
    thr_p = "map_size=512;taps=1;threshold=0.5"
    mom_build_p = "map_size=512;moments=6"

    print("### At equal memory\n")
    print("| scene | CSSM 512² RMSE (memory) | best moments within it: RMSE (setting, memory) "
          "| deep 512², 3 nodes RMSE (memory) | best moments within it: RMSE (setting, memory) |")
    print("|---|---|---|---|---|")
    wins = {"cssm": 0, "deep": 0}
    counted = {"cssm": 0, "deep": 0}
    for s in scenes:
        cells = [s]
        for name, p in (("cssm", cssm_p), ("deep", deep_p)):
            o = find(rows, s, name, p)
            if not o:
                cells += ["-", "-"]
                continue
            m = best_moments(rows, s, num(o, "memory_bytes"))
            cells.append("%.4f (%s)" % (num(o, "rmse"), mib(num(o, "memory_bytes"))))
            if m:
                counted[name] += 1
                win = num(m, "rmse") < num(o, "rmse")
                wins[name] += win
                cells.append("%s%.4f%s (%s, %s)" % ("**" if win else "", num(m, "rmse"),
                                                     "**" if win else "", m["label"],
                                                     mib(num(m, "memory_bytes"))))
            else:
                cells.append("none fits")
        print("| " + " | ".join(cells) + " |")
    print("\nMoments beat CSSM on %d of %d scenes and the 3-node deep map on %d of %d "
          "(bold: moments lower).\n" % (wins["cssm"], counted["cssm"], wins["deep"],
                                          counted["deep"]))

    print("### Build and lookup cost (512² maps)\n")
    print("| scene | threshold build ms | moments (6, 32 bits) build ms | ratio "
          "| render over unshadowed: threshold / CSSM / deep 3 nodes / moments |")
    print("|---|---|---|---|---|")
    for s in scenes:
        t, m = find(rows, s, "threshold", thr_p), find(rows, s, "moments", mom_build_p)
        c, d = find(rows, s, "cssm", cssm_p), find(rows, s, "deep", deep_p)
        if not (t and m):
            continue
        over = " / ".join("%.2f" % num(x, "render_overhead") if x else "-" for x in (t, c, d, m))
        print("| %s | %.1f | %.1f | %.2f | %s |" % (s, num(t, "build_ms"), num(m, "build_ms"),
                                                   num(m, "build_ms") / num(t, "build_ms"), over))

    print("\n### Pareto front over bytes per map texel\n")
    print("| scene | bytes per texel | RMSE | technique, setting |")
    print("|---|---|---|---|")
    for s in scenes:
        front = [r for r in rows if r["scene"] == s and r.get("pareto_texel") == "1"]
        front.sort(key=lambda r: num(r, "bytes_per_texel"))
        for r in front:
            print("| %s | %.3g | %.4f | %s, %s |" % (s, num(r, "bytes_per_texel"), num(r, "rmse"),
                                                    r["technique"], r["label"]))


if __name__ == "__main__":
    main()
