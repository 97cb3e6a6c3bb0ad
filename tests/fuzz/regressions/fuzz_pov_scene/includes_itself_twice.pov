// fuzz_pov_scene writes its input as scene.pov: this file includes itself twice per level.
#include "scene.pov"
#include "scene.pov"
