// Internal: a VisibilityTracer's trace() written on top of RayQueries::occluded(),
// for backends whose strength is not the bake (the brute-force oracle).
#pragma once

#include "skybake/visibility.h"

namespace skybake::visibility {

// Fills chunk.words by one occluded() batch per vertex: the rays of its
// directions on or above the horizon.
void trace_with_queries(const RayQueries& queries, const TraceRule& rule, const TraceChunk& chunk);

} // namespace skybake::visibility
