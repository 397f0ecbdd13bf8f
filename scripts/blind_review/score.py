"""Score a blind review: recognition, believability and the confusion table per set.

Usage: ``score.py ROOT`` (ROOT holds private_key.json and answers.csv).
"""
import csv, json, sys
from collections import Counter, defaultdict
root = sys.argv[1]
key = {k["id"]: k for k in json.load(open(f"{root}/private_key.json"))}
rows = list(csv.DictReader(open(f"{root}/answers.csv")))
E = ["happiness", "sadness", "surprise", "anger", "fear", "disgust", "neutral"]
for phase in sorted({k["phase"] for k in key.values()}):
    conf = defaultdict(Counter); bel = []; hits = Counter(); tot = Counter()
    for r in rows:
        k = key[int(r["id"])]
        if k["phase"] != phase: continue
        said = r["emotion"].strip().lower()
        conf[k["emotion"]][said] += 1
        bel.append(float(r["believability"]))
        lvl = "neutral" if k["emotion"] == "neutral" else ("100%" if k["intensity"] == 1.0 else "50%")
        tot[lvl] += 1; hits[lvl] += said == k["emotion"]
    allh = sum(hits.values()); allt = sum(tot.values())
    print(f"\n{phase}: recognised {allh}/{allt} = {100*allh/allt:.0f}%  (100%: {100*hits['100%']/tot['100%']:.0f}%, 50%: {100*hits['50%']/tot['50%']:.0f}%, neutral: {hits['neutral']}/{tot['neutral']}); believability mean {sum(bel)/len(bel):.2f} (min {min(bel):.0f}, max {max(bel):.0f})")
    print("| shown \\ named | " + " | ".join(e[:4] for e in E) + " |")
    print("|---" * (len(E) + 1) + "|")
    for e in E:
        print(f"| {e} | " + " | ".join(str(conf[e][x]) for x in E) + " |")
