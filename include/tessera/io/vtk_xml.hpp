// VTK XML writers (our own; linking VTK into the core would be far too heavy).
// Binary appended data (raw, little-endian, UInt64 headers) so large meshes are fast.
#pragma once

#include <string>

#include "tessera/cells.hpp"

namespace tessera::io {

/// 3D cells -> .vtu with one VTK_POLYHEDRON (42) per cell; 2D cells -> .vtp with
/// one polygon per cell. Points: the merged vertices. Cell data: GeneratorId
/// (Int32), Region (Int32), Volume (Float64; "Area" in 2D), NumberOfFaces (Int32;
/// "NumberOfEdges" in 2D), NumberOfNeighbors (Int32). Requires cells built with
/// build_mesh. Written atomically. Throws InputError on a bad extension for the
/// dimension (.vtu for 3D, .vtp for 2D) or an unwritable path.
void write_cells_vtk(const std::string& path, const Cells& cells);

}  // namespace tessera::io
