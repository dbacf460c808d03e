import subprocess, time, statistics, sys
trees = {"before": "/work/wt-before", "head": "/work/main"}
times = {k: [] for k in trees}
for i in range(8):
    for name, root in trees.items():
        cmd = [f"{root}/build-bench/apps/chimera/chimera", "run", "/work/main/examples/fig4_pid_joint.yaml", "--clock", "virtual", "--for", "300s"]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times[name].append(time.perf_counter() - t0)
for name, ts in times.items():
    print(name, "median speedup %.0fx" % (300 / statistics.median(ts)), "min..max %.0f..%.0fx" % (300 / max(ts), 300 / min(ts)), "runs", len(ts))
