# Sourced by the rank benchmarks (bench/*/ranks.sh), from the repository's root: sets `exe` to SPATTER
# when given (a spatter built with the `mpi` feature), else builds spatter in release with the feature;
# sets `work` to a temporary folder removed on exit.
target="${CARGO_TARGET_DIR:-target}"
if [ -n "${SPATTER:-}" ]; then
    exe="$SPATTER"
else
    cargo build --release -p spatter-cli --features mpi --locked
    exe="$target/release/spatter"
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
