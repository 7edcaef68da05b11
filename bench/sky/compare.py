"""Joins Campanile's and scipy's sky fits of the same references (bench/sky/run.sh)
and prints one markdown row per group of skies: errors against the references
(noise-free; and with 2% noise, Campanile's robust path against scipy's plain
LM on its own noise draw) and time per channel, with the ratios: Campanile's
whole fit (starts, every candidate, the model choice: what users run) and
Campanile's Levenberg-Marquardt of the Perez form alone from the same start
scipy is given (the like-for-like figure), each against scipy's LM. With a third
file (the example's three.csv), one more row: Campanile's plain fit of a sky's
three channels, one after another and side by side with rayon, against three
times scipy's median per channel (scipy fits one channel at a time)."""
import csv, sys, statistics as st

ours = {(r["id"], r["channel"]): r for r in csv.DictReader(open(sys.argv[1]))}
theirs = {}
for r in csv.DictReader(open(sys.argv[2])):
    theirs.setdefault((r["id"], r["channel"]), {})[float(r["noise"])] = r

def group(sky_id):
    if sky_id.startswith("cie"):
        return "CIE 1-15"
    return "gendaylit bin " + sky_id.split("-")[1][3:]

rows = {}
for key, o in ours.items():
    t = theirs.get(key)
    if not t or 0.0 not in t:
        continue
    rows.setdefault(group(key[0]), []).append((o, t))

def pct(x):
    return f"{100 * x:.3f}%"

print("| skies | channels | Campanile median / p95 / max error | scipy LM median / p95 / max | Campanile with 2% noise, median / p95 | scipy with 2% noise "
      "| Campanile whole fit per channel | Campanile LM alone (Perez form, same start) | scipy LM per channel | speed-up whole fit / LM alone |")
print("|---|---|---|---|---|---|---|---|---|---|")
allo, allt, alll = [], [], []
for g in sorted(rows, key=lambda s: (s.startswith("CIE"), s)):
    rs = rows[g]
    o_med = st.median(float(o["median_err"]) for o, _ in rs)
    o_p95 = max(float(o["p95_err"]) for o, _ in rs)
    o_max = max(float(o["max_err"]) for o, _ in rs)
    t_med = st.median(float(t[0.0]["median_err"]) for _, t in rs)
    t_p95 = max(float(t[0.0]["p95_err"]) for _, t in rs)
    t_max = max(float(t[0.0]["max_err"]) for _, t in rs)
    o_nm = st.median(float(o["noisy_median_err"]) for o, _ in rs)
    o_np = st.median(float(o["noisy_p95_err"]) for o, _ in rs)
    noisy = [t.get(0.02) for _, t in rs if t.get(0.02)]
    t_nm = st.median(float(n["median_err"]) for n in noisy) if noisy else float("nan")
    t_np = st.median(float(n["p95_err"]) for n in noisy) if noisy else float("nan")
    o_ms = st.median(float(o["plain_ms"]) for o, _ in rs)
    l_ms = st.median(float(o["lm_ms"]) for o, _ in rs)
    t_ms = st.median(float(t[0.0]["time_ms"]) for _, t in rs)
    allo += [float(o["plain_ms"]) for o, _ in rs]
    alll += [float(o["lm_ms"]) for o, _ in rs]
    allt += [float(t[0.0]["time_ms"]) for _, t in rs]
    print(f"| {g} | {len(rs)} | {pct(o_med)} / {pct(o_p95)} / {pct(o_max)} | {pct(t_med)} / {pct(t_p95)} / {pct(t_max)} "
          f"| {pct(o_nm)} / {pct(o_np)} | {pct(t_nm)} / {pct(t_np)} | {o_ms:.3f} ms | {l_ms:.3f} ms | {t_ms:.2f} ms "
          f"| {t_ms / o_ms:.1f}× / {t_ms / l_ms:.1f}× |")
print(f"| all | {len(allo)} | | | | | {st.median(allo):.3f} ms | {st.median(alll):.3f} ms | {st.median(allt):.2f} ms "
      f"| {st.median(allt) / st.median(allo):.1f}× / {st.median(allt) / st.median(alll):.1f}× |")
ev = [int(o["evaluations"]) for o in ours.values()]
ns = [float(o["plain_ms"]) * 1e6 / max(1, int(o["samples_evaluated"])) for o in ours.values() if int(o["evaluations"]) > 0]
nf = [int(t[0.0]["nfev"]) for t in theirs.values() if 0.0 in t and t[0.0]["nfev"]]
lm_ev = [int(o["lm_evaluations"]) for o in ours.values()]
lm_ns = [float(o["lm_ms"]) * 1e6 / (int(o["lm_evaluations"]) * int(o["n"])) for o in ours.values() if int(o["lm_evaluations"]) > 0]
lm_gap = max(abs(float(o["lm_p95_err"]) - float(theirs[k][0.0]["p95_err"])) for k, o in ours.items() if k in theirs and 0.0 in theirs[k])
print()
if len(sys.argv) > 3:
    three = [r for r in csv.DictReader(open(sys.argv[3])) if r["channels"] == "3"]
    if three:
        per_channel = st.median(allt)
        print(f"| all, 3 channels together | {len(three)} skies | | | | "
              f"| {st.median(float(r['serial_ms']) for r in three):.2f} ms one after another, "
              f"{st.median(float(r['parallel_ms']) for r in three):.2f} ms with rayon | {3 * per_channel:.2f} ms (3 × median) "
              f"| {3 * per_channel / st.median(float(r['serial_ms']) for r in three):.1f}× / "
              f"{3 * per_channel / st.median(float(r['parallel_ms']) for r in three):.1f}× |")
print(f"Campanile: median {st.median(ev)} Levenberg-Marquardt evaluations (residuals and Jacobian) per channel over all candidates; "
      f"{st.median(ns):.0f} ns of fit time per sample evaluated; by candidate, medians: Perez form (one or two starts) "
      f"{st.median(int(o['perez_evaluations']) for o in ours.values())}, seven-parameter "
      f"{st.median(int(o['seven_evaluations']) for o in ours.values())}, fixed aureole "
      f"{st.median(int(o['fixed_evaluations']) for o in ours.values())} (0: not fitted). "
      f"scipy: median {st.median(nf)} function evaluations per fit (its Jacobian analytic, counted apart).")
print(f"Campanile LM alone (Perez form from scipy's start): median {st.median(lm_ev)} evaluations, {st.median(lm_ns):.1f} ns per sample evaluated; "
      f"its p95 error within {100 * lm_gap:.4f} points of scipy's on every channel.")
