// SPDX-License-Identifier: MIT
// A unit sphere resting on the plane y = 0 (contact point at the origin), for tests/povray:
// exact normals (SSAOPass=1), an AO reference (SSAOPass=2; on the plane the cosine-weighted sky
// visibility is V = 1 - r^3 / (rho^2 + r^2)^(3/2) at a distance rho from the contact point), and
// the bridge's opt-in normal pass. Uses povray_bridge/pov/ssao_passes.inc (+L that folder).
#version 3.7;
#include "ssao_passes.inc"
global_settings { assumed_gamma 1.0 }

#declare CamLocation = <2, 4.5, -6>;
#declare CamLookAt = <0, 0.5, 0>;
camera {
  perspective
  location CamLocation
  right x * image_width / image_height
  up y
  angle 55
  look_at CamLookAt
}
SSAOCameraBasis(CamLocation, CamLookAt)

#if (SSAOBeauty)
  light_source { <-4, 10, -3> rgb 0.8 }
  light_source { <6, 6, -8> rgb 0.4 shadowless }
  background { rgb <0.55, 0.7, 0.9> }
#end

plane { y, 0
  SSAOTexture(texture { pigment { checker rgb 0.85 rgb 0.6 scale 0.5 } finish { diffuse 0.8 } })
}
sphere { <0, 1, 0>, 1
  SSAOTexture(texture { pigment { rgb <0.9, 0.5, 0.3> } finish { diffuse 0.8 specular 0.3 }
                        normal { bumps 0.3 scale 0.1 } })
}
