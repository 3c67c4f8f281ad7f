#!/usr/bin/env bash
# scripts/install-deps.sh's two sets, read with --list (nothing installed): README's main command
# (scripts/demo.sh) installs the build and run set, without Slurm, munge or the test libraries;
# scripts/test.sh asks for the test set too, and that set provides every program
# tests/tools/slurm_test.sh needs (checked against dpkg where they are installed: the package
# owning each program is in the set or a dependency of one in it).
# Usage: install_deps_test.sh SOURCE_DIR
set -uo pipefail
src=$(readlink -f "$1")
fail=0
bad() {
  echo "install_deps_test: $*"
  fail=1
}
default=$("$src/scripts/install-deps.sh" --list) || bad "--list failed"
tests=$("$src/scripts/install-deps.sh" --tests --list) || bad "--tests --list failed"
for p in slurm-wlm munge libgtest-dev libbenchmark-dev pybind11-dev python3-pytest; do
  grep -qx "$p" <<<"$default" && bad "the default set installs $p"
  grep -qx "$p" <<<"$tests" || bad "the --tests set lacks $p"
done
for p in $default; do
  grep -qx "$p" <<<"$tests" || bad "the --tests set lacks $p of the default set"
done
for p in libembree-dev libopenimageio-dev python3-matplotlib cmake; do
  grep -qx "$p" <<<"$default" || bad "the default set lacks $p"
done
"$src/scripts/install-deps.sh" --bogus >/dev/null 2>&1
[ $? -eq 2 ] || bad "an unknown option is not refused with exit code 2"

# Who asks for which set.
grep -Eq '^scripts/install-deps.sh( |$)' "$src/scripts/demo.sh" || bad "demo.sh: no install-deps.sh"
grep -q 'install-deps.sh.*--tests' "$src/scripts/demo.sh" && bad "demo.sh installs the test set"
grep -Eq '^scripts/install-deps.sh --tests' "$src/scripts/test.sh" ||
  bad "test.sh does not install the test set"

# The programs of slurm_test.sh come from the --tests set (or what its packages depend on); one
# dpkg call each for all of them (each call costs about a second on a loaded machine).
# shellcheck disable=SC2086
provided=$tests$'\n'$(dpkg-query -W -f='${Depends}\n' $tests 2>/dev/null | tr ',|' '\n\n' |
  awk '{print $1}')
paths=()
for b in munged slurmctld slurmd sbatch squeue sinfo; do
  if path=$(command -v "$b"); then
    paths+=("$(readlink -f "$path")")
  else
    echo "install_deps_test: $b not installed here: its package not checked"
  fi
done
if [ ${#paths[@]} -gt 0 ]; then
  while IFS=: read -r owner path; do
    grep -qx "$owner" <<<"$provided" || bad "${path# } comes from $owner, which the --tests set lacks"
  done < <(dpkg -S "${paths[@]}" 2>/dev/null)
fi
[ "$fail" -eq 0 ] && echo "install_deps_test: ok"
exit "$fail"
