#!/bin/bash
# Builds and runs the OpenFOAM wedge case and exports the flow-field fixture used by spatter's tests
# and examples/deposition_wedge.toml.
#
#   scripts/openfoam/run_wedge.sh [output dir]   (default: tests/fixtures/openfoam/wedge)
#
# Needs the Debian package `openfoam` (OpenFOAM v1912: blockMesh, surfaceFeatureExtract, snappyHexMesh,
# simpleFoam, foamToVTK) and python3. Runs serially; a few minutes on one core (simpleFoam alone: 18 s
# wall-clock, 6.9 s CPU, in tests/fixtures/openfoam/wedge/simpleFoam_tail.txt; see docs/flow.md §5).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-$root/tests/fixtures/openfoam/wedge}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r "$here/wedge/." "$work/"
mkdir -p "$work/constant/triSurface"
python3 "$here/make_wedge_stl.py" "$work/constant/triSurface/wedge.stl"
# OpenFOAM's environment (its bashrc expects bash-like variables to be unset; relax -u meanwhile).
set +u
source /usr/share/openfoam/etc/bashrc
set -u
cd "$work"
blockMesh > log.blockMesh
surfaceFeatureExtract > log.surfaceFeatureExtract
snappyHexMesh -overwrite > log.snappyHexMesh
checkMesh > log.checkMesh || true
simpleFoam > log.simpleFoam
# XML (.vtu, binary appended) with cell and point data, and the same field as a legacy .vtk.
foamToVTK -latestTime -fields '(U k epsilon)' -no-boundary -name vtk_xml > log.foamToVTK
# The legacy copy (velocity only, to keep the fixture small) checks the legacy reader on real data.
foamToVTK -latestTime -fields '(U)' -no-boundary -legacy -name vtk_legacy > log.foamToVTK.legacy
mkdir -p "$out"
cp "$(find vtk_xml -name 'internal.vtu' | head -n 1)" "$out/internal.vtu"
cp "$(find vtk_legacy -name '*.vtk' | head -n 1)" "$out/internal.vtk"
cp constant/triSurface/wedge.stl "$out/wedge.stl"
# The same body finely triangulated (about 2 cm): deposits are counted per triangle.
python3 "$here/make_wedge_stl.py" "$out/wedge_fine.stl" --cell 0.02
grep -E '^(Mesh stats|    cells:|    points:|    hexahedra:|    prisms:|    polyhedra:|.*bounding box|.*Total volume|Mesh OK|.*Failed)' log.checkMesh > "$out/checkMesh.txt" || true
tail -n 30 log.simpleFoam > "$out/simpleFoam_tail.txt"
echo "wrote $out"
ls -l "$out"
