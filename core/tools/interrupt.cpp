// SPDX-License-Identifier: MIT
#include "tools/interrupt.h"

#include <csignal>

namespace ssao_tools {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_interrupt(int) { g_interrupted = 1; }

}  // namespace

InterruptGuard::InterruptGuard() {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  ::sigaction(SIGINT, &action, &previous_sigint_);
  ::sigaction(SIGTERM, &action, &previous_sigterm_);
}

InterruptGuard::~InterruptGuard() {
  ::sigaction(SIGINT, &previous_sigint_, nullptr);
  ::sigaction(SIGTERM, &previous_sigterm_, nullptr);
}

bool InterruptGuard::interrupted() { return g_interrupted != 0; }

int InterruptGuard::cancel_if_interrupted(void*, double) { return interrupted() ? 0 : 1; }

}  // namespace ssao_tools
