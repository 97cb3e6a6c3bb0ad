// SPDX-License-Identifier: MIT
#include "tools/tool_main.h"

#include <cstdio>
#include <exception>
#include <new>

#include "tools/param_flags.h"

namespace ssao_tools {

int tool_main(const char* name, const std::function<int()>& body) {
  try {
    return body();
  } catch (const UsageError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: error: %s\nTry '%s --help' for more information.\n", name, e.what(),
                 name);
    return 2;
  } catch (const std::bad_alloc&) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: error: out of memory\n", name);
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
  } catch (...) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: error: unexpected exception\n", name);
  }
  return 1;
}

}  // namespace ssao_tools
