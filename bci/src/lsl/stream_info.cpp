#include "arbci/bci/lsl/stream_info.h"

#include <pugixml.hpp>

#include <cstdio>
#include <sstream>

#include "arbci/bci/lsl/config.h"

namespace arbci::bci::lsl {
namespace {

void addText(pugi::xml_node& parent, const char* name, const std::string& value) {
  parent.append_child(name).append_child(pugi::node_pcdata).set_value(value.c_str());
}

// Numbers as liblsl writes them: shortest round-trip text.
std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

void build(const StreamInfo& s, pugi::xml_document& doc, bool full) {
  pugi::xml_node info = doc.append_child("info");
  addText(info, "name", s.name);
  addText(info, "type", s.type);
  addText(info, "channel_count", std::to_string(s.channel_count));
  addText(info, "channel_format", formatName(s.channel_format));
  addText(info, "source_id", s.source_id);
  addText(info, "nominal_srate", number(s.nominal_srate));
  addText(info, "version",
          std::to_string(s.version / 100) + "." + std::to_string(s.version / 10 % 10) +
              (s.version % 10 ? std::to_string(s.version % 10) : ""));
  addText(info, "created_at", number(s.created_at));
  addText(info, "uid", s.uid);
  addText(info, "session_id", s.session_id);
  addText(info, "hostname", s.hostname);
  addText(info, "v4address", s.v4address);
  addText(info, "v4data_port", std::to_string(s.v4data_port));
  addText(info, "v4service_port", std::to_string(s.v4service_port));
  addText(info, "v6address", "");
  addText(info, "v6data_port", "0");
  addText(info, "v6service_port", "0");
  pugi::xml_node desc = info.append_child("desc");
  if (!full) return;
  if (!s.channels.empty()) {
    pugi::xml_node channels = desc.append_child("channels");
    for (const auto& c : s.channels) {
      pugi::xml_node channel = channels.append_child("channel");
      addText(channel, "label", c.label);
      if (!c.unit.empty()) addText(channel, "unit", c.unit);
      if (!c.type.empty()) addText(channel, "type", c.type);
      if (!c.impedance.empty()) addText(channel, "impedance", c.impedance);
    }
  }
  if (!s.parameters.empty()) {
    pugi::xml_node arbci = desc.append_child("arbci");
    for (const auto& [name, value] : s.parameters) {
      pugi::xml_node parameter = arbci.append_child("parameter");
      parameter.append_attribute("name").set_value(name.c_str());
      parameter.append_child(pugi::node_pcdata).set_value(value.c_str());
    }
  }
}

int wholeNumber(const pugi::xml_node& info, const char* field, int low, int high) {
  const std::string text = info.child_value(field);
  try {
    size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size() && v >= low && v <= high) return v;
  } catch (const std::exception&) {
  }
  throw LslError(std::string("stream info: <") + field + "> is \"" + text +
                 "\", not a whole number from " + std::to_string(low) + " to " +
                 std::to_string(high));
}

double realNumber(const pugi::xml_node& info, const char* field) {
  const std::string text = info.child_value(field);
  try {
    size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw LslError(std::string("stream info: <") + field + "> is \"" + text + "\", not a number");
}

}  // namespace

const char* formatName(ChannelFormat format) {
  switch (format) {
    case ChannelFormat::Float32:
      return "float32";
    case ChannelFormat::Double64:
      return "double64";
    case ChannelFormat::String:
      return "string";
    case ChannelFormat::Int32:
      return "int32";
    case ChannelFormat::Int16:
      return "int16";
    case ChannelFormat::Int8:
      return "int8";
    case ChannelFormat::Int64:
      return "int64";
  }
  return "undefined";
}

ChannelFormat formatFromName(const std::string& name) {
  for (ChannelFormat f :
       {ChannelFormat::Float32, ChannelFormat::Double64, ChannelFormat::String,
        ChannelFormat::Int32, ChannelFormat::Int16, ChannelFormat::Int8, ChannelFormat::Int64})
    if (name == formatName(f)) return f;
  throw LslError("stream info: channel format \"" + name +
                 "\" is not one of float32, double64, string, int32, int16, int8, int64");
}

int formatSize(ChannelFormat format) {
  switch (format) {
    case ChannelFormat::Float32:
      return 4;
    case ChannelFormat::Double64:
      return 8;
    case ChannelFormat::String:
      return 0;
    case ChannelFormat::Int32:
      return 4;
    case ChannelFormat::Int16:
      return 2;
    case ChannelFormat::Int8:
      return 1;
    case ChannelFormat::Int64:
      return 8;
  }
  return 0;
}

std::string StreamInfo::toXml(bool full) const {
  pugi::xml_document doc;
  build(*this, doc, full);
  std::ostringstream out;
  doc.save(out);
  return out.str();
}

StreamInfo StreamInfo::fromXml(const std::string& xml) {
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(xml.data(), xml.size());
  if (!parsed)
    throw LslError(std::string("stream info: not well-formed XML (") + parsed.description() +
                   " at byte " + std::to_string(parsed.offset) + ")");
  const pugi::xml_node info = doc.child("info");
  if (!info) throw LslError("stream info: no <info> element");
  StreamInfo s;
  s.name = info.child_value("name");
  if (s.name.empty()) throw LslError("stream info: the stream has no <name>");
  s.type = info.child_value("type");
  s.channel_count = wholeNumber(info, "channel_count", 0, 1 << 20);
  s.nominal_srate = realNumber(info, "nominal_srate");
  if (s.nominal_srate < 0) throw LslError("stream info: <nominal_srate> is negative");
  s.channel_format = formatFromName(info.child_value("channel_format"));
  s.source_id = info.child_value("source_id");
  s.version = static_cast<int>(realNumber(info, "version") * 100 + 0.5);
  s.created_at = realNumber(info, "created_at");
  s.uid = info.child_value("uid");
  if (s.uid.empty()) throw LslError("stream info: the stream \"" + s.name + "\" has no <uid>");
  s.session_id = info.child_value("session_id");
  s.hostname = info.child_value("hostname");
  s.v4address = info.child_value("v4address");
  s.v4data_port = wholeNumber(info, "v4data_port", 0, 65535);
  s.v4service_port = wholeNumber(info, "v4service_port", 0, 65535);
  for (pugi::xml_node c = info.child("desc").child("channels").child("channel"); c;
       c = c.next_sibling("channel"))
    s.channels.push_back({c.child_value("label"), c.child_value("unit"), c.child_value("type"),
                          c.child_value("impedance")});
  for (pugi::xml_node p : info.child("desc").child("arbci").children("parameter"))
    s.parameters.emplace_back(p.attribute("name").value(), p.child_value());
  return s;
}

bool StreamInfo::matches(const std::string& query) const {
  if (query.empty()) return true;
  pugi::xml_document doc;
  build(*this, doc, false);
  try {
    const pugi::xpath_query compiled(query.c_str());
    return compiled.evaluate_boolean(doc.first_child());
  } catch (const pugi::xpath_exception& e) {
    throw LslError("LSL query \"" + query + "\" is not valid XPath: " + e.what());
  }
}

std::vector<std::string> StreamInfo::channelLabels() const {
  std::vector<std::string> labels;
  for (int c = 0; c < channel_count; ++c) {
    const bool named = c < static_cast<int>(channels.size()) && !channels[c].label.empty();
    labels.push_back(named ? channels[c].label : std::string("Ch").append(std::to_string(c + 1)));
  }
  return labels;
}

std::string buildQuery(const std::string& session_id, const std::string& name,
                       const std::string& type, const std::string& source_id,
                       const std::string& hostname) {
  std::string query;
  for (const auto& [field, value] : {std::pair<std::string, std::string>{"session_id", session_id},
                                     {"name", name},
                                     {"type", type},
                                     {"source_id", source_id},
                                     {"hostname", hostname}}) {
    if (value.empty()) continue;
    if (value.find('\'') != std::string::npos)
      throw LslError("LSL " + field + " \"" + value +
                     "\" contains a single quote, which a query "
                     "cannot express");
    if (!query.empty()) query += " and ";
    query += field;
    query += "='";
    query += value;
    query += "'";
  }
  return query;
}

}  // namespace arbci::bci::lsl
