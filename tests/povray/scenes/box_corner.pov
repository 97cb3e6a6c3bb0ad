// SPDX-License-Identifier: MIT
// A corner of two walls on a floor, with a box pushed into the corner and a ball on the floor,
// for the AO comparison in tests/povray/test_povray.py against POV-Ray's own radiosity AO
// (SSAOPass=2). The camera comes from ssao_passes.inc's SSAOCamera macro.
#version 3.7;
#include "ssao_passes.inc"
global_settings { assumed_gamma 1.0 }

SSAOCamera(<3.2, 3.6, -5.5>, <-0.6, 0.7, 1.0>, 55)

#if (SSAOBeauty)
  light_source { <3, 9, -6> rgb 0.9 area_light 2*x, 2*z, 3, 3 adaptive 1 jitter }
  light_source { <-2, 4, -10> rgb 0.3 shadowless }
  background { rgb <0.6, 0.7, 0.9> }
#end

#declare Paint = texture { pigment { rgb <0.85, 0.82, 0.75> } finish { diffuse 0.8 } }

plane { y, 0 SSAOTexture(texture { pigment { checker rgb 0.8 rgb 0.55 } finish { diffuse 0.8 } }) }
box { <-3.2, 0, -2>, <-3, 3, 3.2> SSAOTexture(Paint) }      // left wall, inner face x = -3
box { <-3.2, 0, 3>, <3, 3, 3.2> SSAOTexture(Paint) }        // back wall, inner face z = 3
box { <-3, 0, 1.8>, <-1.8, 1.2, 3>                          // box in the corner
  SSAOTexture(texture { pigment { rgb <0.5, 0.6, 0.8> } finish { diffuse 0.8 specular 0.2 } })
}
sphere { <0.9, 0.6, 0.3>, 0.6
  SSAOTexture(texture { pigment { rgb <0.9, 0.4, 0.3> } finish { diffuse 0.8 phong 0.4 } })
}
