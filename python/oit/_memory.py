"""How much memory the machine has to allocate: the CPU reference's guard (`oit.reference`)."""

from __future__ import annotations

import os


def available_memory() -> int | None:
    """Bytes of memory available to allocate (Linux MemAvailable, else physical memory), or
    None where neither is known."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None
