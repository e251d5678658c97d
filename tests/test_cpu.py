"""Physical cores: hardware threads of one core count once, CPUs without a readable topology count alone."""

from __future__ import annotations

import platform

import sid.cpu
from sid.cpu import keep_freed_memory, physical_cores, usable_cpus


def fake_topology(root, siblings: dict[int, str]) -> None:
    for cpu, text in siblings.items():
        folder = root / f"cpu{cpu}" / "topology"
        folder.mkdir(parents=True)
        (folder / "thread_siblings_list").write_text(text + "\n")


def test_smt_siblings_count_once(tmp_path, monkeypatch):
    fake_topology(tmp_path, {0: "0,2", 1: "1,3", 2: "0,2", 3: "1,3"})
    monkeypatch.setattr(sid.cpu, "_TOPOLOGY", tmp_path)
    assert physical_cores(range(4)) == 2
    assert physical_cores([0, 2]) == 1  # a process allowed on both threads of one core


def test_cpus_without_topology_count_as_cores(tmp_path, monkeypatch):
    monkeypatch.setattr(sid.cpu, "_TOPOLOGY", tmp_path)
    assert physical_cores([0, 1, 5]) == 3
    assert physical_cores([]) == 1


def test_this_machine_has_at_least_one_core_per_usable_cpu_set():
    assert 1 <= physical_cores() <= len(usable_cpus())


def test_keep_freed_memory_applies_on_glibc():
    applied = keep_freed_memory()
    assert applied == (platform.libc_ver()[0] == "glibc")
    assert keep_freed_memory() == applied  # idempotent: every worker and every command may call it
