"""Sum the logs of ``TUMBLE_COMPILE_PROFILE`` (tests/compile_profile.py): where a cold test suite's CPU goes.

    NUMBA_CACHE_DIR=$(mktemp -d) TUMBLE_COMPILE_PROFILE=/tmp/profile python -m pytest -n 2
    python benchmarks/compile_report.py /tmp/profile [--top 30]

Prints three tables, CPU seconds: per test file (tests, CPU in the test process, of which compiling, CPU of
the subprocesses the tests started); the compiled functions
by self compile time (how many compilations, how many tests triggered one, the signatures); the tests by CPU.
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path


def read(directory: Path) -> list[dict]:
    """Every test record of every process's log in ``directory``."""
    return [json.loads(line) for log in sorted(directory.glob("*.jsonl")) for line in log.read_text().splitlines()]


def compile_seconds(record: dict) -> float:
    """The CPU seconds a test spent compiling: the sum of its compilations' self times."""
    return sum(entry[3] for entry in record["compiles"])


def per_file(records: list[dict]) -> list[tuple[str, int, float, float, float]]:
    """(file, tests, CPU, compile CPU, subprocess CPU) by file, most CPU first."""
    files: dict[str, list] = defaultdict(lambda: [0, 0.0, 0.0, 0.0])
    for record in records:
        row = files[record["test"].split("::")[0]]
        row[0] += 1
        row[1] += record["cpu"]
        row[2] += compile_seconds(record)
        row[3] += record.get("children", 0.0)
    return sorted(((name, *row) for name, row in files.items()), key=lambda row: -row[2] - row[4])


def per_function(records: list[dict]) -> list[tuple[str, int, int, float, set[str]]]:
    """(function, compilations, tests that compiled it, self compile CPU, signatures), most CPU first."""
    functions: dict[str, list] = defaultdict(lambda: [0, set(), 0.0, set()])
    for record in records:
        for name, signature, _inclusive, own, _depth in record["compiles"]:
            row = functions[name]
            row[0] += 1
            row[1].add(record["test"])
            row[2] += own
            row[3].add(signature)
    return sorted(((name, count, len(tests), seconds, signatures)
                   for name, (count, tests, seconds, signatures) in functions.items()), key=lambda row: -row[3])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directory", type=Path)
    parser.add_argument("--top", type=int, default=30)
    args = parser.parse_args()
    records = read(args.directory)
    total = sum(record["cpu"] for record in records)
    compiling = sum(compile_seconds(record) for record in records)
    children = sum(record.get("children", 0.0) for record in records)
    print(f"{len(records)} tests: {total:.1f} CPU s in tests, {compiling:.1f} of them compiling; "
          f"{children:.1f} CPU s in their subprocesses\n")
    print("| test file | tests | CPU s | compile CPU s | subprocess CPU s |\n| --- | ---: | ---: | ---: | ---: |")
    for name, tests, cpu, own, sub in per_file(records):
        print(f"| {name} | {tests} | {cpu:.1f} | {own:.1f} | {sub:.1f} |")
    print("\n| compiled function | compilations | tests | self CPU s | signatures |\n| --- | ---: | ---: | ---: | ---: |")
    for name, count, tests, own, signatures in per_function(records)[:args.top]:
        print(f"| {name} | {count} | {tests} | {own:.1f} | {len(signatures)} |")
    print("\n| test | CPU s | compile CPU s | subprocess CPU s |\n| --- | ---: | ---: | ---: |")
    for record in sorted(records, key=lambda record: -record["cpu"] - record.get("children", 0.0))[:args.top]:
        print(f"| {record['test']} | {record['cpu']:.1f} | {compile_seconds(record):.1f} | "
              f"{record.get('children', 0.0):.1f} |")


if __name__ == "__main__":
    main()
