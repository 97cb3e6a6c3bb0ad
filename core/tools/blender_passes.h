// SPDX-License-Identifier: MIT
// Finds the render passes (depth, normal, beauty) among the channel names of an EXR file.
//
// Blender's "OpenEXR MultiLayer" files name channels <layer>.<pass>.<component>:
//   depth   <layer>.Depth.Z
//   normal  <layer>.Normal.X, <layer>.Normal.Y, <layer>.Normal.Z
//   beauty  <layer>.Combined.R, .G, .B and, if present, .A
//   extra depth layers (the add-on's and scripts/blender/render_layers.py's, not Blender's own)
//           <layer>.Depth2.Z with <layer>.Facing2.V, <layer>.Depth3.Z with .Facing3.V, ...
// The layer is the view layer's name ("ViewLayer" by default, any name in general, possibly
// with dots). Every channel ending in ".Depth.Z" names a candidate layer; when there are several
// the caller must choose one (--layer), the error lists them.
//
// Files without layers are accepted too. Depth is looked up, in this order, as
//   Depth.Z, Z, depth, Depth
// normals as Normal.{X,Y,Z} then N.{X,Y,Z}, beauty as Combined.{R,G,B[,A]} then R, G, B[, A],
// extra depth layers as Depth2.Z (Facing2.V), Depth3.Z, ... up to the first missing one.
// Any of the three can be named explicitly instead (PassOverrides).
#pragma once

#include <string>
#include <vector>

#include "tools/error.h"

namespace ssao_tools {

// Extra depth layers the library takes: the 2nd to the 5th hit ("depth2" ... "depth5").
constexpr size_t kMaxDepthLayers = 4;

struct DepthLayerChannels {
  std::string depth;
  std::string facing;  // "" = none (the library takes the hits to alternate)
};

struct PassOverrides {
  std::string layer;                             // "" = detect
  std::string depth_channel;                     // "" = detect
  std::vector<std::string> normal_channels;      // empty = detect, else exactly 3 names
  std::vector<std::string> beauty_channels;      // empty = detect, else 3 or 4 names
  bool no_normals = false;                       // ignore the normal pass entirely
  std::vector<DepthLayerChannels> depth_layers;  // empty = detect
  bool no_depth_layers = false;                  // ignore extra depth layers entirely
};

struct PassChannels {
  std::string layer;                             // "" for a file without layers
  std::string depth;                             // always set
  std::vector<std::string> normal;               // empty or X, Y, Z
  std::vector<std::string> beauty;               // empty or R, G, B[, A]
  std::vector<DepthLayerChannels> depth_layers;  // the 2nd, 3rd, ... hit; may be empty
};

// The view layers that have a depth pass ("<layer>.Depth.Z"), in channel order.
std::vector<std::string> layers_with_depth(const std::vector<std::string>& channels);

// Chooses the channels to use. `file` only appears in messages. Throws Error when no depth
// channel is found (the message lists the channels that exist), when several layers have a
// depth pass and none was chosen, or when an explicitly named channel or layer does not exist.
PassChannels detect_passes(const std::vector<std::string>& channels, const PassOverrides& overrides,
                           const std::string& file);

}  // namespace ssao_tools
