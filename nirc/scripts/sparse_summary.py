# Sparse grid updates against dense ones, paired by seed: two folders of runs of the same
# scenarios and seeds (SCENE-seedN/frames.csv, as statistics_experiment.sh writes them), one with
# `optimizer: (sparse_grid: true)`. Per scene and NIRC method, the window means of FLIP after the
# change and SMAPE before it (steady state), sparse minus dense per seed, then the mean ± 95%
# interval (Student t over seeds). Usage:
#   python3 nirc/scripts/sparse_summary.py DENSE_RUNS SPARSE_RUNS [change_frame]
import collections, csv, math, os, re, sys

dense_dir, sparse_dir = sys.argv[1], sys.argv[2]
change = int(sys.argv[3]) if len(sys.argv) > 3 else 20
windows = {'FLIP after': ('flip', change + 2, 10**9), 'SMAPE before': ('smape', change - 10, change - 1),
           'ms nirc_train': ('gpu_ms_nirc_train', 0, 10**9)}
T975 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262}


def window_means(runs):
    out = collections.defaultdict(dict)  # (scene, method, window) -> {seed: mean}
    for name in sorted(os.listdir(runs)):
        m = re.fullmatch(r'(.+)-seed(\d+)', name)
        path = os.path.join(runs, name, 'frames.csv')
        if not m or not os.path.exists(path):
            continue
        rows = [r for r in csv.DictReader(open(path)) if r['method'].startswith('nirc_')]
        for label, (col, a, b) in windows.items():
            by = collections.defaultdict(list)
            for r in rows:
                if a <= int(r['frame']) <= b and r.get(col, '') not in ('', None):
                    by[r['method']].append(float(r[col]))
            for method, v in by.items():
                out[(m.group(1), method, label)][int(m.group(2))] = sum(v) / len(v)
    return out


dense, sparse = window_means(dense_dir), window_means(sparse_dir)
print('| scene | method | ' + ' | '.join(f'{w}: dense | sparse − dense' for w in windows) + ' | seeds |')
print('|---|---|' + '---:|---:|' * len(windows) + '---|')
for scene, method in sorted({(s, m) for s, m, _ in dense}):
    cells, seeds = [], []
    for w in windows:
        d, s = dense.get((scene, method, w), {}), sparse.get((scene, method, w), {})
        seeds = sorted(set(d) & set(s))
        diff = [s[k] - d[k] for k in seeds]
        n = len(diff)
        mu = sum(diff) / n if n else float('nan')
        half = T975.get(n - 1, 1.96) * math.sqrt(sum((x - mu) ** 2 for x in diff) / (n - 1) / n) if n > 1 else float('nan')
        base = sum(d[k] for k in seeds) / n if n else float('nan')
        cells.append(f'{base:.4f} | {mu:+.4f} ± {half:.4f}')
    print(f"| {scene} | {method} | {' | '.join(cells)} | {','.join(map(str, seeds))} |")
