// SPDX-License-Identifier: MIT
// A floor whose occluders stand just outside the frame (a low box beyond the bottom edge,
// a pillar beyond each side edge, 1 to 11 pixels out at 160x120) and one box inside it, for
// povray-ssao's guard band (--overscan) in tests/povray/test_povray.py: without the band the
// floor along the edges cannot know about them. The camera comes from ssao_passes.inc's
// SSAOCamera macro; every box is axis-aligned so that the test can ray-cast the visibility.
#version 3.7;
#include "ssao_passes.inc"
global_settings { assumed_gamma 1.0 }

SSAOCamera(<0, 4, -6>, <0, 0, 0>, 60)

#if (SSAOBeauty)
  light_source { <-3, 10, -5> rgb 0.9 }
  background { rgb <0.6, 0.7, 0.9> }
#end

#declare Paint = texture { pigment { rgb <0.85, 0.82, 0.75> } finish { diffuse 0.8 } }

plane { y, 0 SSAOTexture(texture { pigment { checker rgb 0.8 rgb 0.55 } finish { diffuse 0.8 } }) }
box { <-1.5, 0, -4.4>, <1.5, 0.25, -3.62> SSAOTexture(Paint) }  // below the bottom edge
box { <-5.8, 0, -2>, <-4.75, 1.5, 0> SSAOTexture(Paint) }       // left of the left edge
box { <4.75, 0, -2>, <5.8, 1.5, 0> SSAOTexture(Paint) }         // right of the right edge
box { <-0.6, 0, 1>, <0.6, 1, 2> SSAOTexture(Paint) }            // in the frame
