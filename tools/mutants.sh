#!/usr/bin/env bash
# Mutation testing of the CPU twins with cargo-mutants (issue 43): every mutant of the named
# files is built and run against the CPU-side tests, and the caught share is reported.
# Not run by CI (a mutant rebuilds the library: about 30 s each on the 2-core VM).
#
#   bash tools/mutants.sh                      # the modules the guide's testing chapter lists
#   bash tools/mutants.sh src/budget.rs        # one file (globs allowed: 'src/shade/*.rs')
#
# Installs cargo-mutants (from crates.io, pinned) on first use. Results land in
# target/mutants/mutants.out (caught.txt, missed.txt, timeout.txt, unviable.txt).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! cargo mutants --version >/dev/null 2>&1; then
    cargo install --locked cargo-mutants --version 27.1.0
fi
files=("$@")
if [ ${#files[@]} -eq 0 ]; then
    files=('src/shade/*.rs' 'src/reference/*.rs' 'src/bake/*.rs' src/render/soft.rs
        src/render/temporal.rs src/render/volume.rs src/budget.rs src/fsutil.rs)
fi
args=()
for f in "${files[@]}"; do
    args+=(--file "$f")
done
# The CPU-side tests: the unit tests and the integration tests that need no GPU. Given to every
# cargo invocation (-C), so a mutant's build links only these binaries.
targets=(--lib --test=generator --test=shading_twin --test=bake_file --test=bake_cli
    --test=deform --test=dynamics --test=export)
cargo_args=()
for t in "${targets[@]}"; do
    cargo_args+=("--cargo-arg=$t")
done
cargo mutants --profile release --output target/mutants "${cargo_args[@]}" "${args[@]}"
