# Summary of a NIRC run folder: per method mean FLIP / SMAPE before and after the change,
# mean ms per frame (all passes) and per pass, reliability stats. Usage: python3 summarise.py RUN [change_frame]
import csv, collections, sys, math
run = sys.argv[1]; change = int(sys.argv[2]) if len(sys.argv) > 2 else None
rows = list(csv.DictReader(open(run + '/frames.csv')))
by = collections.defaultdict(list)
for r in rows: by[r['method']].append(r)
def f(x):
    try: return float(x)
    except: return float('nan')
def mean(v):
    v = [x for x in v if not math.isnan(x)]
    return sum(v) / len(v) if v else float('nan')
print(f"{'method':18} {'ms/frame':>9} {'paths':>7} {'infer':>7} {'train':>7} {'FLIP<':>6} {'FLIP>':>6} {'SMAPE<':>7} {'SMAPE>':>7}")
for m, rs in by.items():
    rs.sort(key=lambda r: int(r['frame']))
    pre = [r for r in rs if change is None or int(r['frame']) < change]
    post = [r for r in rs if change is not None and change + 2 <= int(r['frame'])]
    # Pass times: gpu_ms_PASS where the adapter has timestamp queries, else wall_ms_PASS.
    def col(rr, k):
        if k.startswith('gpu_ms_') and k not in rr[0]:
            k = 'wall_ms_' + k[len('gpu_ms_'):]
        return mean([f(r.get(k, '')) for r in rr])
    print(f"{m:18} {col(rs,'gpu_ms_total'):9.1f} {col(rs,'gpu_ms_nirc_paths'):7.1f} {col(rs,'gpu_ms_nirc_infer'):7.1f} {col(rs,'gpu_ms_nirc_train'):7.1f} {col(pre,'flip'):6.3f} {col(post,'flip'):6.3f} {col(pre,'smape'):7.3f} {col(post,'smape'):7.3f}")
m = next((m for m in by if m.startswith('nirc_blend')), None)
if m:
    rs = sorted(by[m], key=lambda r: int(r['frame']))
    for k in ['reliability_high_lr', 'reliability_ema', 'blend_sigma', 'prefer_high_lr', 'train_loss']:
        v = [f(r[k]) for r in rs]
        print(f"{k:20} first5 {mean(v[:5]):.3f}  last5 {mean(v[-5:]):.3f}  min {min(v):.3f} max {max(v):.3f}")
