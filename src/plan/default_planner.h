// The planner that plan, sweep and the server's Plan use when a request
// names none: the portfolio, never below Algorithm 2 and bounded by 5 x its
// time (docs/results.md). Preview, a quick look, uses the fastest.
#pragma once

namespace hj {

inline constexpr const char* kDefaultPlanner = "portfolio";
inline constexpr const char* kPreviewPlanner = "algorithm2";
// The render loop's: its corrections move the targets of one planner's
// mapping from targets to surface, and the portfolio may switch strategy
// from one iteration to the next (and by the machine's speed), undoing them.
// Algorithm 2 without jams in the sag: from 5 x 8 up Algorithm 2's plans
// jam the sag and a device never leaves it (docs/render.md).
inline constexpr const char* kRenderPlanner = "algorithm2-levelled";

}  // namespace hj
