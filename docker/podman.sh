#!/usr/bin/env bash
# The container image with podman, where no registry is reachable but Debian's mirror is:
# a debian:12 base made locally (debootstrap), the image built from docker/Dockerfile, a scene
# run in it, and docker/compose.yaml's three services (one process each) with podman-compose.
# A benchmark command (minutes: the image compiles the project), not a test.
#   docker/podman.sh [--jobs N]      (root; installs podman, podman-compose, runc, debootstrap)
# Results: runs/podman_sdof (one container, the launcher) and runs/sdof (compose).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=$(nproc)
[ "${1:-}" = "--jobs" ] && JOBS=$2
export CONTAINERS_CONF="$PWD/docker/containers.conf"
missing=()
for p in podman podman-compose runc debootstrap; do command -v "$p" >/dev/null || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then apt-get update && apt-get install -y --no-install-recommends "${missing[@]}"; fi

if ! podman image exists localhost/debian:12; then
  echo "== base image localhost/debian:12 from Debian's mirror (debootstrap)"
  root=$(mktemp -d)
  trap 'rm -rf "$root"' EXIT
  debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian
  tar -C "$root" -c . | podman import - localhost/debian:12
fi

echo "== image fsi-cosim (docker/Dockerfile; the build compiles the project)"
t0=$(date +%s)
podman build --build-arg "JOBS=$JOBS" -f docker/Dockerfile -t fsi-cosim .
echo "image built in $(( $(date +%s) - t0 )) s"

mkdir -p runs
echo "== one container: the launcher runs the SDOF scene"
rm -rf runs/podman_sdof
podman run --rm -v "$PWD/runs:/runs" fsi-cosim run configs/sdof_model.yaml --out /runs/podman_sdof \
  --set coupling.gamma_n1=100
python3 -c "import json; s = json.load(open('runs/podman_sdof/summary.json')); print('one container:', s['status'], s['steps'], 'steps'); assert s['status'] == 'completed'"

echo "== compose: solid, fluid and coupler as three containers (podman-compose)"
rm -rf runs/sdof
podman-compose -p fsi-sdof -f docker/compose.yaml up --abort-on-container-exit --exit-code-from coupler
podman-compose -p fsi-sdof -f docker/compose.yaml down -v
python3 -c "import json; s = json.load(open('runs/sdof/summary.json')); print('compose:', s['status'], s['steps'], 'steps'); assert s['status'] == 'completed'"
