"""The libraries' import graph has no back-arrow: each library includes only itself and the
libraries it may depend on (docs/library.md). Prints one line per offending include; exit 1.

Usage: check_layers.py SOURCE_DIR"""
import pathlib
import re
import sys

# library -> the libraries its sources and headers may include (besides itself).
ALLOWED = {
    "common": set(),
    "records": {"common"},
    "identification": {"common"},
    "model": {"common"},
    "simulation": {"common", "model"},
    "updating": {"common", "model", "simulation"},
    "validation": {"common", "records", "identification", "model", "simulation", "updating"},
    "report": {"common", "records", "identification", "model", "simulation", "updating",
               "validation"},
    "campaign": {"common", "records", "identification", "model", "simulation", "updating",
                 "validation", "report"},
    "facade": {"common", "records", "identification", "model", "simulation", "updating",
               "validation", "report"},
    "app": {"common", "records", "identification", "model", "simulation", "updating",
            "validation", "report", "campaign", "facade"},
}
# Where a library's headers are: mbid/<name>/ (the facade's one header is mbid/mbid.h).
INCLUDE = re.compile(r'^\s*#\s*include\s+[<"]mbid/(?:(\w+)/|(mbid\.h))')

root = pathlib.Path(sys.argv[1])
problems = []
checked = 0
for library, allowed in ALLOWED.items():
    for path in sorted((root / library).rglob("*")):
        if path.suffix not in (".h", ".cc") or not path.is_file():
            continue
        checked += 1
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            match = INCLUDE.match(line)
            if not match:
                continue
            target = "facade" if match.group(2) else match.group(1)
            if target != library and target not in allowed:
                problems.append(f"{path.relative_to(root)}:{number}: {library} includes "
                                f"{target} (allowed: {', '.join(sorted(allowed)) or 'none'})")
for problem in problems:
    print(problem)
print(f"check_layers: {checked} files, {len(problems)} back-arrows")
sys.exit(1 if problems else 0)
