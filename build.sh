#!/usr/bin/env bash
# The newcomer's two commands (README):
#   bash build.sh run [SCENARIO]   install what is missing, build, run the validation cycle
#   bash build.sh test             install what is missing, build, run the whole test suite
set -euo pipefail
cd "$(dirname "$0")"

# Debian 12 packages only (docs/install.md says what each is for).
packages=(build-essential cmake ccache pkg-config
  libsimbody-dev libeigen3-dev libsundials-dev libceres-dev libhdf5-dev hdf5-tools zlib1g-dev
  libyaml-cpp-dev libcli11-dev libfmt-dev nlohmann-json3-dev libmuparser-dev libudunits2-dev libmatio-dev libboost-dev
  libgtest-dev libbenchmark-dev gnuplot-nox python3-h5py pybind11-dev python3-dev python3-numpy
  openmpi-bin libopenmpi-dev)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "build.sh: installing ${missing[*]}" >&2
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

build_dir=${MBID_BUILD_DIR:-build}
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build_dir" -j2

case "${1:-run}" in
  run)
    shift || true
    # Again and again into results/<name>/: replacing an earlier run's results is the point.
    "$build_dir/app/mbid" run --overwrite "$@"
    ;;
  test)
    ctest --test-dir "$build_dir" --output-on-failure -j2 --timeout 900
    ;;
  *)
    echo "usage: bash build.sh run [SCENARIO] | bash build.sh test" >&2
    exit 2
    ;;
esac
