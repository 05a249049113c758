"""One line describing the machine a benchmark ran on (CPU model, cores, load, memory)."""

from __future__ import annotations

import os
import platform
from pathlib import Path


def describe() -> str:
    """``"CPU model, N cores usable, load a/b/c, M GiB RAM, Linux x.y"``, from /proc."""
    model = platform.processor() or "unknown CPU"
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.is_file():
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    load = "/".join(f"{x:.1f}" for x in os.getloadavg())
    memory = ""
    meminfo = Path("/proc/meminfo")
    if meminfo.is_file():
        kib = int(meminfo.read_text().split()[1])
        memory = f", {kib / 2**20:.0f} GiB RAM"
    return (f"{model}, {cores} cores usable, load {load}{memory}, "
            f"{platform.system()} {platform.release()}")
