// SPDX-License-Identifier: MIT
// povray-ssao: screen-space ambient occlusion for POV-Ray 3.7 scenes. See --help, options.cpp
// and bridge.cpp; docs/povray.md.
#include <cstdio>

#include "bridge.h"
#include "options.h"
#include "ssao/ssao.hpp"
#include "tools/tool_main.h"

int main(int argc, char** argv) {
  return ssao_tools::tool_main("povray-ssao", [&] {
    const std::vector<ssao_param_desc> table = ssao::api::param_table();
    const povray_ssao::Options options = povray_ssao::parse_args(argc, argv, table);
    if (options.help) {
      std::fputs(povray_ssao::usage_text(table).c_str(), stdout);
    } else if (options.version) {
      std::printf("povray-ssao (libssao %s)\n", ssao::api::version_string(ssao_version()).c_str());
    } else if (options.post_process()) {
      povray_ssao::run_post_process(options);
    } else {
      povray_ssao::run_render(options);
    }
    return 0;
  });
}
