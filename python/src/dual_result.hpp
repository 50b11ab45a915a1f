// The objects behind tessera._core.Graph and tessera._core.Flowers
// (bind_dual.cpp; saved by bind_io.cpp). FaceSet and SurfaceNet are bound as
// the library's own structs.
#pragma once

#include <optional>
#include <vector>

#include "tessera/flower.hpp"
#include "tessera/graph.hpp"

namespace tessera::python {

/// The graph plus its undirected edges, computed on first use and then kept
/// (numpy views point into both; neither is resized once set).
struct GraphResult {
  AdjacencyGraph graph;
  std::optional<GraphEdges> edges;
};

/// The flowers of the requested points, in request order.
struct FlowerSet {
  std::vector<Flower> flowers;
};

}  // namespace tessera::python
