#!/usr/bin/env bash
# Keeps docker/Dockerfile, docker/compose.yaml and .dockerignore honest without a Docker engine:
#  - the Dockerfile starts FROM debian:12 and its RUN steps call scripts/install-deps.sh and then
#    scripts/build.sh (the scripts CI runs, so CI covers what the image does);
#  - every scripts/... path and COPY source they name exists, and .dockerignore leaves them in;
#  - compose.yaml parses (python3 + PyYAML) and has the services plant, controller, trajectory,
#    monitor and lcm-logger, each with network_mode: host, each running its own executable;
#  - every feeddrive-* executable the Dockerfile or compose.yaml names is one CMake builds
#    (add_executable, including the foreach over roles in service/CMakeLists.txt).
# Usage: dockerfile_test.sh SOURCE_DIR. Prints every failure; exits 1 if there is any.
set -uo pipefail

if [ "$#" -ne 1 ] || [ ! -d "$1" ]; then
  echo "usage: dockerfile_test.sh SOURCE_DIR" >&2
  exit 2
fi
SRC=$(cd "$1" && pwd)
DOCKERFILE=docker/Dockerfile
COMPOSE=docker/compose.yaml
failures=0
checks=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
pass() { checks=$((checks + 1)); }

for f in "$DOCKERFILE" "$COMPOSE" .dockerignore scripts/install-deps.sh scripts/build.sh; do
  if [ -f "$SRC/$f" ]; then pass; else fail "$f does not exist"; fi
done
if [ ! -f "$SRC/$DOCKERFILE" ] || [ ! -f "$SRC/$COMPOSE" ]; then
  echo "dockerfile_test: FAILED ($failures failures)" >&2
  exit 1
fi

# --- Dockerfile --------------------------------------------------------------------------------
# Instructions one per line: comments dropped, backslash continuations joined.
instructions=$(sed -e 's/^[[:space:]]*#.*$//' "$SRC/$DOCKERFILE" | sed -e ':a' -e '/\\$/{N;s/\\\n/ /;ba' -e '}' |
  grep -v '^[[:space:]]*$')

from=$(printf '%s\n' "$instructions" | grep -iE '^[[:space:]]*FROM[[:space:]]' | head -1 | awk '{print $2}')
if [ "$from" = "debian:12" ]; then pass; else fail "$DOCKERFILE: first FROM is '$from', expected debian:12"; fi

run_lines=$(printf '%s\n' "$instructions" | grep -niE '^[[:space:]]*RUN[[:space:]]')
deps_line=$(printf '%s\n' "$run_lines" | grep -E 'bash[[:space:]]+scripts/install-deps\.sh' | head -1 | cut -d: -f1)
build_line=$(printf '%s\n' "$run_lines" | grep -E 'bash[[:space:]]+scripts/build\.sh' | head -1 | cut -d: -f1)
if [ -n "$deps_line" ]; then pass; else fail "$DOCKERFILE: no RUN line calls 'bash scripts/install-deps.sh'"; fi
if [ -n "$build_line" ]; then pass; else fail "$DOCKERFILE: no RUN line calls 'bash scripts/build.sh'"; fi
if [ -n "$deps_line" ] && [ -n "$build_line" ]; then
  if [ "$deps_line" -lt "$build_line" ]; then pass; else
    fail "$DOCKERFILE: the RUN of scripts/install-deps.sh must come before the RUN of scripts/build.sh"
  fi
fi
# The dependency layer is built from install-deps.sh alone, copied before the rest of the tree.
copy_deps=$(printf '%s\n' "$instructions" | grep -nE '^[[:space:]]*COPY[[:space:]].*scripts/install-deps\.sh' | head -1 | cut -d: -f1)
if [ -n "$copy_deps" ] && [ -n "$deps_line" ] && [ "$copy_deps" -lt "$deps_line" ]; then pass; else
  fail "$DOCKERFILE: expected 'COPY scripts/install-deps.sh ...' before the RUN of install-deps.sh (layer caching)"
fi

# COPY/ADD sources exist in the build context (the repository root).
while read -r line; do
  # Drop the instruction and --flags; every word but the last is a source.
  read -r -a words <<<"$(printf '%s\n' "$line" | sed -E 's/^[[:space:]]*(COPY|ADD)[[:space:]]+//I; s/--[a-z-]+=[^[:space:]]+[[:space:]]*//g')"
  n=${#words[@]}
  for ((i = 0; i < n - 1; i++)); do
    if [ -e "$SRC/${words[$i]}" ]; then pass; else fail "$DOCKERFILE: COPY source '${words[$i]}' does not exist"; fi
  done
done < <(printf '%s\n' "$instructions" | grep -iE '^[[:space:]]*(COPY|ADD)[[:space:]]')

# Every scripts/... path named by the Dockerfile or compose.yaml exists.
while read -r path; do
  [ -z "$path" ] && continue
  if [ -f "$SRC/$path" ]; then pass; else fail "script $path (named in $DOCKERFILE or $COMPOSE) does not exist"; fi
done < <(grep -ohE 'scripts/[A-Za-z0-9_./-]*[A-Za-z0-9_]' "$SRC/$DOCKERFILE" "$SRC/$COMPOSE" | sort -u)

# --- compose.yaml, .dockerignore, CMake executables (python3 + PyYAML) --------------------------
if ! python3 -c 'import yaml' 2>/dev/null; then
  fail "python3 with PyYAML is needed to check $COMPOSE (Debian: apt-get install python3-yaml)"
  echo "dockerfile_test: FAILED ($failures failures)" >&2
  exit 1
fi

py_out=$(python3 - "$SRC" "$DOCKERFILE" "$COMPOSE" <<'PY'
import fnmatch, os, re, sys
import yaml

src, dockerfile, compose = sys.argv[1:4]
fails, passes = [], 0

def check(ok, message):
    global passes
    if ok:
        passes += 1
    else:
        fails.append(message)

# compose.yaml parses and has the five services, all on the host network.
try:
    with open(os.path.join(src, compose)) as f:
        doc = yaml.safe_load(f)
except yaml.YAMLError as e:
    print("FAIL: %s does not parse as YAML: %s" % (compose, e))
    print("PASSES 0")
    sys.exit(0)
services = doc.get("services") if isinstance(doc, dict) else None
check(isinstance(services, dict), "%s: no 'services' mapping" % compose)
services = services if isinstance(services, dict) else {}
expected = {"plant": "feeddrive-plant", "controller": "feeddrive-controller",
            "trajectory": "feeddrive-trajectory", "monitor": "feeddrive-monitor",
            "lcm-logger": "lcm-logger"}
images = set()
for name, exe in expected.items():
    svc = services.get(name)
    check(isinstance(svc, dict), "%s: no service '%s'" % (compose, name))
    if not isinstance(svc, dict):
        continue
    check(svc.get("network_mode") == "host",
          "%s: service %s has network_mode %r, expected host (LCM multicast)" % (compose, name, svc.get("network_mode")))
    command = svc.get("command")
    words = command if isinstance(command, list) else str(command or "").split()
    words = [str(w) for w in words]
    check(any(w == exe or re.search(r"(^|[\s/])%s(\s|$)" % re.escape(exe), w) for w in words),
          "%s: service %s does not run %s (command: %r)" % (compose, name, exe, command))
    images.add(svc.get("image"))
    build = svc.get("build")
    if build is not None:
        context = build if isinstance(build, str) else build.get("context", ".")
        context = os.path.normpath(os.path.join(src, os.path.dirname(compose), context))
        df = "Dockerfile" if isinstance(build, str) else build.get("dockerfile", "Dockerfile")
        check(os.path.realpath(os.path.join(context, df)) == os.path.realpath(os.path.join(src, dockerfile)),
              "%s: service %s builds %s in context %s, not %s" % (compose, name, df, context, dockerfile))
check(len(images) == 1 and None not in images,
      "%s: the services should share one image, found %r" % (compose, sorted(map(str, images))))

with open(os.path.join(src, compose)) as f:
    compose_text = f.read()
with open(os.path.join(src, dockerfile)) as f:
    dockerfile_text = f.read()

# Scenario files compose names (e.g. the default of FEEDDRIVE_SCENARIO) exist.
for path in sorted(set(re.findall(r"scenarios/[A-Za-z0-9_./-]+\.ya?ml", compose_text))):
    check(os.path.isfile(os.path.join(src, path)), "%s: scenario %s does not exist" % (compose, path))

# .dockerignore leaves in what the image build needs.
patterns = []
with open(os.path.join(src, ".dockerignore")) as f:
    for line in f:
        line = line.strip()
        if line and not line.startswith("#"):
            patterns.append(line)
def ignored(path):
    out = False
    parts = path.split("/")
    prefixes = ["/".join(parts[:i]) for i in range(1, len(parts) + 1)]
    for p in patterns:
        neg = p.startswith("!")
        pat = p[1:] if neg else p
        pat = pat.strip("/")
        if any(fnmatch.fnmatchcase(q, pat) and q.count("/") == pat.count("/") for q in prefixes):
            out = not neg
    return out
needed = ["CMakeLists.txt", "scripts/install-deps.sh", "scripts/build.sh", dockerfile]
needed += re.findall(r"scenarios/[A-Za-z0-9_./-]+\.ya?ml", compose_text)
for path in sorted(set(needed)):
    check(not ignored(path), ".dockerignore excludes %s, which the image needs" % path)
check(ignored("build") and ignored(".git"), ".dockerignore should exclude build and .git")

# Executables CMake builds: add_executable(NAME ...), with foreach(VAR ITEMS...) expanded.
built = set()
skip = re.compile(r"^(build.*|\.git|out)$")
for root, dirs, files in os.walk(src):
    dirs[:] = [d for d in dirs if not skip.match(d)]
    if "CMakeLists.txt" not in files:
        continue
    with open(os.path.join(root, "CMakeLists.txt")) as f:
        text = re.sub(r"#[^\n]*", "", f.read())
    for m in re.finditer(r"foreach\s*\(\s*(\w+)\s+([^)]*)\)(.*?)endforeach", text, re.S | re.I):
        var, items, body = m.group(1), m.group(2).split(), m.group(3)
        for name in re.findall(r"add_executable\s*\(\s*([^\s)]+)", body, re.I):
            for item in items:
                built.add(name.replace("${%s}" % var, item))
    for name in re.findall(r"add_executable\s*\(\s*([^\s)]+)", text, re.I):
        if "${" not in name:
            built.add(name)
check(any(n.startswith("feeddrive-") for n in built), "no feeddrive-* add_executable found in any CMakeLists.txt")
for label, text in ((dockerfile, dockerfile_text), (compose, compose_text)):
    for exe in sorted(set(re.findall(r"(?<![\w.-])feeddrive-[a-z0-9]+(?:-[a-z0-9]+)*", text))):
        check(exe in built, "%s names %s, which no CMakeLists.txt builds (built: %s)"
              % (label, exe, ", ".join(sorted(n for n in built if n.startswith("feeddrive-")))))

for message in fails:
    print("FAIL: " + message)
print("PASSES %d" % passes)
PY
)
py_rc=$?
if [ "$py_rc" -ne 0 ]; then fail "the python3 part of the check crashed (exit $py_rc)"; fi
while IFS= read -r line; do
  case "$line" in
    "FAIL: "*) fail "${line#FAIL: }" ;;
    "PASSES "*) checks=$((checks + ${line#PASSES })) ;;
  esac
done <<<"$py_out"

if [ "$failures" -ne 0 ]; then
  echo "dockerfile_test: FAILED ($failures failures, $checks checks passed)" >&2
  exit 1
fi
echo "dockerfile_test: $checks checks passed"
