// SPDX-License-Identifier: MIT
#include "tools/blender_passes.h"

#include <algorithm>

#include "tools/image_io.h"

namespace ssao_tools {
namespace {

const char* const kDepthSuffix = ".Depth.Z";

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string with_layer(const std::string& layer, const std::string& rest) {
  return layer.empty() ? rest : layer + "." + rest;
}

// "<base>.<c>" for every component c when all of them exist, else empty.
std::vector<std::string> find_group(const std::vector<std::string>& channels,
                                    const std::string& base,
                                    const std::vector<std::string>& components) {
  std::vector<std::string> names;
  for (const std::string& component : components) {
    const std::string name = base.empty() ? component : base + "." + component;
    if (!contains(channels, name)) return {};
    names.push_back(name);
  }
  return names;
}

// R, G, B and, when present, A.
std::vector<std::string> find_color(const std::vector<std::string>& channels,
                                    const std::string& base) {
  std::vector<std::string> names = find_group(channels, base, {"R", "G", "B"});
  const std::string alpha = base.empty() ? "A" : base + ".A";
  if (!names.empty() && contains(channels, alpha)) names.push_back(alpha);
  return names;
}

void require_named(const std::vector<std::string>& channels, const std::vector<std::string>& names,
                   const std::string& what, const std::string& file) {
  for (const std::string& name : names) {
    if (!contains(channels, name)) {
      throw Error("'" + file + "' has no channel '" + name + "' (" + what +
                  "); its channels are: " + join_names(channels));
    }
  }
}

std::string choose_layer_and_depth(const std::vector<std::string>& channels,
                                   const PassOverrides& overrides, const std::string& file,
                                   PassChannels& out) {
  if (!overrides.depth_channel.empty()) {
    require_named(channels, {overrides.depth_channel}, "depth channel", file);
    out.depth = overrides.depth_channel;
    if (!overrides.layer.empty()) return overrides.layer;
    if (ends_with(out.depth, kDepthSuffix) && out.depth.size() > std::string(kDepthSuffix).size()) {
      return out.depth.substr(0, out.depth.size() - std::string(kDepthSuffix).size());
    }
    return "";
  }

  const std::vector<std::string> layers = layers_with_depth(channels);
  if (!overrides.layer.empty()) {
    const std::string name = overrides.layer + kDepthSuffix;
    if (!contains(channels, name)) {
      throw Error("'" + file + "' has no view layer '" + overrides.layer +
                  "' with a depth pass (no channel '" + name + "'); " +
                  (layers.empty() ? "no layer has one; its channels are: " + join_names(channels)
                                  : "layers with a depth pass: " + join_names(layers)));
    }
    out.depth = name;
    return overrides.layer;
  }
  if (layers.size() > 1) {
    throw Error("'" + file + "' has several view layers with a depth pass: " + join_names(layers) +
                "; choose one with --layer");
  }
  if (layers.size() == 1) {
    out.depth = layers.front() + kDepthSuffix;
    return layers.front();
  }
  for (const char* plain : {"Depth.Z", "Z", "depth", "Depth"}) {
    if (contains(channels, plain)) {
      out.depth = plain;
      return "";
    }
  }
  throw Error("'" + file + "' has no depth channel (looked for <layer>.Depth.Z, Depth.Z, Z, " +
              "depth, Depth); its channels are: " + join_names(channels) +
              "; name the depth channel with --depth-channel");
}

// <layer>.Depth2.Z (with <layer>.Facing2.V when present), Depth3.Z, ... up to the first missing.
std::vector<DepthLayerChannels> find_depth_layers(const std::vector<std::string>& channels,
                                                  const std::string& layer) {
  std::vector<DepthLayerChannels> found;
  for (size_t hit = 2; hit < 2 + kMaxDepthLayers; ++hit) {
    const std::string depth = with_layer(layer, "Depth" + std::to_string(hit) + ".Z");
    const std::string facing = with_layer(layer, "Facing" + std::to_string(hit) + ".V");
    if (!contains(channels, depth)) break;
    found.push_back({depth, contains(channels, facing) ? facing : ""});
  }
  return found;
}

}  // namespace

std::vector<std::string> layers_with_depth(const std::vector<std::string>& channels) {
  const size_t suffix_length = std::string(kDepthSuffix).size();
  std::vector<std::string> layers;
  for (const std::string& channel : channels) {
    if (channel.size() > suffix_length && ends_with(channel, kDepthSuffix)) {
      const std::string layer = channel.substr(0, channel.size() - suffix_length);
      if (!contains(layers, layer)) layers.push_back(layer);
    }
  }
  return layers;
}

PassChannels detect_passes(const std::vector<std::string>& channels, const PassOverrides& overrides,
                           const std::string& file) {
  PassChannels out;
  out.layer = choose_layer_and_depth(channels, overrides, file, out);

  if (!overrides.no_normals) {
    if (!overrides.normal_channels.empty()) {
      if (overrides.normal_channels.size() != 3) {
        throw Error("normal channels: expected 3 names (X,Y,Z), got " +
                    std::to_string(overrides.normal_channels.size()));
      }
      require_named(channels, overrides.normal_channels, "normal channel", file);
      out.normal = overrides.normal_channels;
    } else if (!out.layer.empty()) {
      out.normal = find_group(channels, with_layer(out.layer, "Normal"), {"X", "Y", "Z"});
    } else {
      out.normal = find_group(channels, "Normal", {"X", "Y", "Z"});
      if (out.normal.empty()) out.normal = find_group(channels, "N", {"X", "Y", "Z"});
    }
  }

  if (!overrides.depth_layers.empty()) {
    for (const DepthLayerChannels& named : overrides.depth_layers) {
      require_named(channels, {named.depth}, "depth layer channel", file);
      if (!named.facing.empty()) require_named(channels, {named.facing}, "facing channel", file);
    }
    out.depth_layers = overrides.depth_layers;
  } else if (!overrides.no_depth_layers) {
    out.depth_layers = find_depth_layers(channels, out.layer);
  }

  if (!overrides.beauty_channels.empty()) {
    if (overrides.beauty_channels.size() != 3 && overrides.beauty_channels.size() != 4) {
      throw Error("beauty channels: expected 3 or 4 names (R,G,B[,A]), got " +
                  std::to_string(overrides.beauty_channels.size()));
    }
    require_named(channels, overrides.beauty_channels, "beauty channel", file);
    out.beauty = overrides.beauty_channels;
  } else if (!out.layer.empty()) {
    out.beauty = find_color(channels, with_layer(out.layer, "Combined"));
  } else {
    out.beauty = find_color(channels, "Combined");
    if (out.beauty.empty()) out.beauty = find_color(channels, "");
  }
  return out;
}

}  // namespace ssao_tools
