// SPDX-License-Identifier: MIT
// povray-ssao: screen-space ambient occlusion for POV-Ray 3.7 scenes. See --help, options.cpp
// and bridge.cpp; docs/povray.md.
#include <cstdio>
#include <exception>
#include <new>

#include "bridge.h"
#include "io/job.h"
#include "options.h"

int main(int argc, char** argv) {
  try {
    const std::vector<ssao_param_desc> table = ssao_io::param_table();
    const povray_ssao::Options options = povray_ssao::parse_args(argc, argv, table);
    if (options.help) {
      std::fputs(povray_ssao::usage_text(table).c_str(), stdout);
      return 0;
    }
    if (options.version) {
      std::printf("povray-ssao (libssao %s)\n", ssao_io::version_string(ssao_version()).c_str());
      return 0;
    }
    if (options.post_process()) {
      povray_ssao::run_post_process(options);
    } else {
      povray_ssao::run_render(options);
    }
    return 0;
  } catch (const ssao_io::UsageError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "povray-ssao: error: %s\nTry 'povray-ssao --help' for more information.\n",
                 e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fflush(stdout);
    std::fprintf(stderr, "povray-ssao: error: out of memory\n");
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "povray-ssao: error: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "povray-ssao: error: unexpected exception\n");
  }
  return 1;
}
