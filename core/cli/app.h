// SPDX-License-Identifier: MIT
// What the ssao tool does once its command line is parsed.
#pragma once

#include <vector>

#include "args.h"
#include "tools/error.h"

namespace ssao_cli {

// A sequence in which some frames failed (each was reported; the others were written).
class SequenceFailed : public ssao_tools::Error {
 public:
  using ssao_tools::Error::Error;
};

// Reads the input and the camera, computes AO and writes the output. Throws UsageError for
// command-line mistakes found late (output = input, a value the core rejects), ssao_tools::Error
// for any other failure; in both cases nothing has been written under the output name. With
// --frames, every frame is done on its own (a line per frame on stderr) and SequenceFailed
// reports the frames that failed after the others were written.
void run_ssao(const Options& options);

// --list-chunks: prints "INDEX FRAMES" for each chunk of --frames, one per line, on stdout.
void list_chunks(const Options& options);

}  // namespace ssao_cli
