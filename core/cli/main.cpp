// SPDX-License-Identifier: MIT
// ssao: screen-space ambient occlusion of a rendered EXR. See --help, args.cpp and app.cpp.
#include <cstdio>

#include "app.h"
#include "args.h"
#include "ssao/ssao.hpp"
#include "tools/tool_main.h"

int main(int argc, char** argv) {
  return ssao_tools::tool_main("ssao", [&] {
    const std::vector<ssao_param_desc> table = ssao::api::param_table();
    const ssao_cli::Options options = ssao_cli::parse_args(argc, argv, table);
    if (options.help) {
      std::fputs(ssao_cli::usage_text(table).c_str(), stdout);
    } else if (options.version) {
      std::printf("ssao %s\n", ssao::api::version_string(ssao_version()).c_str());
    } else if (options.list_chunks) {
      ssao_cli::list_chunks(options);
    } else {
      ssao_cli::run_ssao(options);
    }
    return 0;
  });
}
