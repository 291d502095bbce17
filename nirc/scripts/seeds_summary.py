# The NIRC light-rotation experiment over seeds: per scene, method and window, the mean over
# seeds of the per-run window means of FLIP and SMAPE, with a 95% interval (Student t over the
# seeds), and the blend against the fixed-σ control per seed (paired). Usage:
#   python3 nirc/scripts/seeds_summary.py RUNS_DIR [change_frame]
# RUNS_DIR holds SCENE-seedN/frames.csv folders (nirc/scripts/paper_experiment.sh writes them).
import csv, collections, math, os, re, sys

runs = sys.argv[1]
change = int(sys.argv[2]) if len(sys.argv) > 2 else 20
# Windows: steady state before the change, adaptation (2-10 frames after), steady after.
windows = [('before', change - 10, change - 1), ('adapt', change + 2, change + 10), ('after', change + 11, 10**9)]
T975 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262, 10: 2.228}


def f(x):
    try:
        return float(x)
    except ValueError:
        return float('nan')


def mean(v):
    v = [x for x in v if not math.isnan(x)]
    return sum(v) / len(v) if v else float('nan')


def interval(v):
    v = [x for x in v if not math.isnan(x)]
    n = len(v)
    if n < 2:
        return mean(v), float('nan')
    m = sum(v) / n
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1))
    return m, T975.get(n - 1, 1.96) * sd / math.sqrt(n)


# per[scene][method][window][metric] = list over seeds
per = collections.defaultdict(lambda: collections.defaultdict(lambda: collections.defaultdict(lambda: collections.defaultdict(list))))
seeds = collections.defaultdict(list)
for name in sorted(os.listdir(runs)):
    m = re.fullmatch(r'(.+)-seed(\d+)', name)
    path = os.path.join(runs, name, 'frames.csv')
    if not m or not os.path.exists(path):
        continue
    scene, seed = m.group(1), int(m.group(2))
    seeds[scene].append(seed)
    rows = list(csv.DictReader(open(path)))
    by = collections.defaultdict(list)
    for r in rows:
        by[r['method']].append(r)
    for method, rs in by.items():
        for wname, a, b in windows:
            w = [r for r in rs if a <= int(r['frame']) <= b]
            for metric in ('flip', 'smape', 'blend_sigma'):
                per[scene][method][wname][metric].append(mean([f(r.get(metric, '')) for r in w]))

for scene in sorted(per):
    print(f"\n### {scene} (seeds {', '.join(map(str, sorted(seeds[scene])))}; light change at frame {change})\n")
    head = ' | '.join(f'{metric} {w}' for metric in ('FLIP', 'SMAPE') for w, _, _ in windows)
    print(f'| method | {head} |')
    print('|---|' + '---:|' * (2 * len(windows)))
    for method in sorted(per[scene]):
        cells = []
        for metric in ('flip', 'smape'):
            for w, _, _ in windows:
                mu, ci = interval(per[scene][method][w][metric])
                cells.append(f'{mu:.4f} ± {ci:.4f}')
        print(f"| {method} | {' | '.join(cells)} |")
    blend = next((m for m in per[scene] if m.startswith('nirc_blend')), None)
    fixed = next((m for m in per[scene] if m.startswith('nirc_fixed')), None)
    if blend and fixed:
        print(f'\nBlend minus fixed-σ control (paired over seeds, mean ± 95% interval; negative = blend better):\n')
        for metric in ('flip', 'smape'):
            for w, _, _ in windows:
                d = [x - y for x, y in zip(per[scene][blend][w][metric], per[scene][fixed][w][metric])]
                mu, ci = interval(d)
                print(f'- {metric} {w}: {mu:+.4f} ± {ci:.4f}')
        for w, _, _ in windows:
            mu, ci = interval(per[scene][blend][w]['blend_sigma'])
            print(f'- mean σ of the blend, {w}: {mu:.3f} ± {ci:.3f}')
