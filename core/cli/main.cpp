// SPDX-License-Identifier: MIT
// ssao: screen-space ambient occlusion of a rendered EXR. See --help, args.cpp and app.cpp.
#include <cstdio>
#include <exception>
#include <new>

#include "app.h"
#include "args.h"
#include "io/job.h"

int main(int argc, char** argv) {
  try {
    const std::vector<ssao_param_desc> table = ssao_io::param_table();
    const ssao_cli::Options options = ssao_cli::parse_args(argc, argv, table);
    if (options.help) {
      std::fputs(ssao_cli::usage_text(table).c_str(), stdout);
      return 0;
    }
    if (options.version) {
      std::printf("ssao %s\n", ssao_io::version_string(ssao_version()).c_str());
      return 0;
    }
    if (options.list_chunks) {
      ssao_cli::list_chunks(options);
      return 0;
    }
    ssao_cli::run_ssao(options);
    return 0;
  } catch (const ssao_cli::UsageError& e) {
    std::fprintf(stderr, "ssao: error: %s\nTry 'ssao --help' for more information.\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "ssao: error: out of memory\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ssao: error: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "ssao: error: unexpected exception\n");
  }
  return 1;
}
