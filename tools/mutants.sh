#!/usr/bin/env bash
# Mutation testing of the CPU twins with cargo-mutants (issue 43): the mutants of each module
# group are built and run against that group's tests, and the caught share is reported per
# group. Not run by CI: a mutant costs 7-45 s on the 2-core VM (dev profile, which rebuilds only
# the changed codegen unit, plus 3-5 s of tests), and the groups hold 3,196 mutants (~12 h).
# The guide's testing chapter has the measured sample and every survivor.
#
#   bash tools/mutants.sh                  # every group, every mutant (hours on 2 cores)
#   MUTANTS_SHARD=1/10 bash tools/mutants.sh        # a 1-in-10 round-robin sample of each group
#   MUTANTS_SAMPLE=25 bash tools/mutants.sh         # about 25 mutants of each group, evenly spaced
#   MUTANTS_SAMPLE=20 MUTANTS_OFFSET=5 bash tools/mutants.sh   # another sample, disjoint from shard 1
#   bash tools/mutants.sh shade io         # named groups only
#   MUTANTS_ITERATE=1 bash tools/mutants.sh reference  # only what the last run did not catch
#
# Groups (files -> tests): shade (src/shade -> unit tests, shading_twin), reference
# (src/reference -> unit tests, generator, gpu_oracle, lhs, volume), bake (src/bake -> unit tests,
# bake_file, bake_cli, deform, generator, hair_mesh_update, gpu_oracle), render (the CPU halves of the soft raster,
# temporal and volume features -> unit tests, volume), io (budget.rs, fsutil.rs -> unit tests,
# bake_cli, export). A CPU twin's first guard is its GPU comparison (gpu_oracle, shading_twin,
# hair_mesh_update, volume: a few seconds each on lavapipe), so those run with their group.
#
# Runs in place in a scratch worktree (target/mutants-tree; builds in target/mutants-build,
# seeded from target/debug and kept), so the checkout can be edited meanwhile. Installs cargo-mutants
# (from crates.io, pinned) on first use. Results: target/mutants/<group>/mutants.out (caught.txt,
# missed.txt, timeout.txt, unviable.txt) and a summary line per group on stdout.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
if ! cargo mutants --version >/dev/null 2>&1; then
    cargo install --locked cargo-mutants --version 27.1.0
fi

declare -A files tests
files[shade]="src/shade/*.rs"
tests[shade]="--lib --test=shading_twin"
files[reference]="src/reference/*.rs"
tests[reference]="--lib --test=generator --test=gpu_oracle --test=lhs --test=volume"
files[bake]="src/bake/*.rs"
tests[bake]="--lib --test=bake_file --test=bake_cli --test=deform --test=generator --test=hair_mesh_update --test=gpu_oracle"
files[render]="src/render/features/soft_raster/mod.rs src/render/features/temporal/mod.rs src/render/features/volume/mod.rs"
tests[render]="--lib --test=volume"
files[io]="src/budget.rs src/fsutil.rs"
tests[io]="--lib --test=bake_cli --test=export"

groups=("$@")
[ ${#groups[@]} -eq 0 ] && groups=(shade reference bake render io)

# The GPU-recording halves of the render files (pass declarations, buffer descriptors, the
# dispatch plumbing) are exercised only by the GPU tests: left out of the CPU twin's score.
exclude_render='DensityVolumes::|check_sampling|SoftBudget::buffers|shadow_buffers|transient_buffers|frame_fields|TemporalState::|VolumePass|fn record|::record|descriptor'

tree="$root/target/mutants-tree"
# Builds go to one folder kept between runs (seeded once from target/debug where there is one, so the dependencies
# are not rebuilt); the sources are a fresh worktree each run (a stopped run may leave a mutant).
export CARGO_TARGET_DIR="$root/target/mutants-build"
mkdir -p "$CARGO_TARGET_DIR"
if [ ! -d "$CARGO_TARGET_DIR/debug" ] && [ -d "$root/target/debug" ]; then
    cp -a "$root/target/debug" "$CARGO_TARGET_DIR/debug"
fi
rm -rf "$tree"
git worktree prune
git worktree add --detach "$tree" HEAD >/dev/null
git diff HEAD >"$root/target/mutants-uncommitted.diff"
# Each group starts from the checkout as it is: a mutant that writes where it should not (an
# output path turned into an input, say) must not leave a broken tree for the next group.
fresh_tree() {
    (cd "$tree" && git reset -q --hard HEAD && git clean -qfdx && \
        git apply --allow-empty "$root/target/mutants-uncommitted.diff")
}

for g in "${groups[@]}"; do
    [ -n "${files[$g]:-}" ] || { echo "mutants.sh: unknown group '$g'" >&2; exit 2; }
    fresh_tree
    # Which mutants (also what --list counts for a sample) and what tests them.
    # The library only: the workspace's Bevy plugin is not built for mutants.
    select=(--package hairmesh)
    for f in ${files[$g]}; do select+=(--file "$f"); done
    for t in ${tests[$g]}; do select+=("--cargo-arg=$t"); done
    [ "$g" = render ] && select+=(--exclude-re "$exclude_render")
    args=(--in-place --dir "$tree" --output "$root/target/mutants/$g" --no-shuffle
        --minimum-test-timeout 60 "${select[@]}")
    shard=${MUTANTS_SHARD:-}
    if [ -n "${MUTANTS_SAMPLE:-}" ]; then
        total=$(cd "$tree" && cargo mutants --list "${select[@]}" | grep -c .)
        k=$(( (total + MUTANTS_SAMPLE - 1) / MUTANTS_SAMPLE ))
        # MUTANTS_OFFSET picks another of the k round-robin shards: a sample independent of
        # the ones before (the 2026-12-05 sample was shard 1).
        shard="$(( ${MUTANTS_OFFSET:-1} % k ))/$k"
        echo "$g: $total mutants, sampling $shard"
    fi
    [ -n "$shard" ] && args+=(--shard "$shard" --sharding round-robin)
    # MUTANTS_ITERATE=1: test again only what the last run of the group did not catch.
    [ -n "${MUTANTS_ITERATE:-}" ] && args+=(--iterate)
    mkdir -p "$root/target/mutants/$g"
    cargo mutants "${args[@]}" >"$root/target/mutants/$g/log.txt" 2>&1 || true
    out="$root/target/mutants/$g/mutants.out"
    count() { if [ -f "$out/$1.txt" ]; then grep -c . "$out/$1.txt" || true; else echo 0; fi; }
    caught=$(count caught) missed=$(count missed) timeout=$(count timeout) unviable=$(count unviable)
    echo "$g: caught $caught, missed $missed, timeout $timeout, unviable $unviable"
done
git worktree remove --force "$tree"
