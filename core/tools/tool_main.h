// SPDX-License-Identifier: MIT
// main() of every tool: runs its body and turns what it throws into a message and an exit
// status, the same way in each program.
#pragma once

#include <functional>

namespace ssao_tools {

// Returns body()'s status, or: 2 for a UsageError ("NAME: error: ..." and a hint to --help),
// 1 for any other exception ("NAME: error: ..."; "out of memory" for std::bad_alloc). stdout
// is flushed before the message so that progress lines and the error keep their order.
int tool_main(const char* name, const std::function<int()>& body);

}  // namespace ssao_tools
