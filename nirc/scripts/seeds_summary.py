# The NIRC light-rotation experiment over seeds: per scene, method and window, the mean over
# seeds of the per-run window means of FLIP and SMAPE, with a 95% interval (Student t over the
# seeds), every NIRC method against the fixed-σ control per seed (paired), and a verdict for each
# blend (better than the fixed mix or not). Usage:
#   python3 nirc/scripts/seeds_summary.py RUNS_DIR [change_frame]
# RUNS_DIR holds SCENE-seedN/frames.csv folders (nirc/scripts/paper_experiment.sh writes them).
import csv, collections, math, os, re, sys

runs = sys.argv[1]
change = int(sys.argv[2]) if len(sys.argv) > 2 else 20
# Windows: steady state before the change, adaptation (2-10 frames after), steady after.
windows = [('before', change - 10, change - 1), ('adapt', change + 2, change + 10), ('after', change + 11, 10**9)]
# Adaptation and steady state together: the after-change window of the verdict.
post = ('post', change + 2, 10**9)
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
        for wname, a, b in windows + [post]:
            w = [r for r in rs if a <= int(r['frame']) <= b]
            for metric in ('flip', 'smape', 'blend_sigma', 'own_sigma'):
                per[scene][method][wname][metric].append(mean([f(r.get(metric, '')) for r in w]))

def paired(scene, method, control, window, metric):
    return [x - y for x, y in zip(per[scene][method][window][metric], per[scene][control][window][metric])]


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
    fixed = next((m for m in per[scene] if m.startswith('nirc_fixed')), None)
    if not fixed:
        continue
    print(f'\nEach method minus the fixed-σ control {fixed} (paired over seeds, mean ± 95% interval; negative = method better):\n')
    print('| method | ' + ' | '.join(f'{metric} {w}' for metric in ('FLIP', 'SMAPE') for w, _, _ in windows + [post]) + ' |')
    print('|---|' + '---:|' * (2 * len(windows) + 2))
    for method in sorted(per[scene]):
        if method == fixed or not method.startswith('nirc_'):
            continue
        cells = []
        for metric in ('flip', 'smape'):
            for w, _, _ in windows + [post]:
                mu, ci = interval(paired(scene, method, fixed, w, metric))
                cells.append(f'{mu:+.4f} ± {ci:.4f}')
        print(f"| {method} | {' | '.join(cells)} |")
    # `blend_sigma` is the shared diagnostic, σ of the paper's blend, in every NIRC row.
    blend = next((m for m in per[scene] if m.startswith('nirc_blend')), None)
    if blend:
        sig = ', '.join('{} {:.3f} ± {:.3f}'.format(w, *interval(per[scene][blend][w]['blend_sigma'])) for w, _, _ in windows)
        print(f"- mean σ of the paper's blend: {sig}")
    for method in sorted(per[scene]):
        if not all(math.isnan(x) for x in per[scene][method]['before']['own_sigma']):
            sig = ', '.join('{} {:.3f} ± {:.3f}'.format(w, *interval(per[scene][method][w]['own_sigma'])) for w, _, _ in windows)
            print(f'- mean σ of {method}: {sig}')

# The verdict (for every blend and switch): better than the fixed mix when its FLIP after the
# change (frames change+2 to the end) is below the fixed mix's beyond the 95% interval of the
# paired difference in at least two scenes, with its steady-state SMAPE (before the change) not
# above the fixed mix's beyond that interval in any scene.
scenes = sorted(per)
fixed_of = {sc: next((m for m in per[sc] if m.startswith('nirc_fixed')), None) for sc in scenes}
candidates = sorted({m for sc in scenes for m in per[sc] if m.startswith(('nirc_blend', 'nirc_switch'))})
if candidates and all(fixed_of.values()):
    print(f'\n### Verdict against the fixed mix (FLIP over frames {change + 2}- , SMAPE over frames {change - 10}-{change - 1})\n')
    for method in candidates:
        wins, smape_worse, notes = 0, 0, []
        for sc in scenes:
            if method not in per[sc]:
                continue
            fm, fc = interval(paired(sc, method, fixed_of[sc], 'post', 'flip'))
            sm, scc = interval(paired(sc, method, fixed_of[sc], 'before', 'smape'))
            wins += fm + fc < 0
            smape_worse += sm - scc > 0
            notes.append(f'{sc} FLIP {fm:+.4f} ± {fc:.4f}, SMAPE {sm:+.4f} ± {scc:.4f}')
        better = wins >= 2 and smape_worse == 0
        print(f"- {method}: {'better' if better else 'not better'} (FLIP lower beyond the interval in {wins} of {len(notes)} scenes, steady SMAPE worse in {smape_worse}): {'; '.join(notes)}")
