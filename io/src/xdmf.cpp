// erodem — the XDMF sidecar of a result file (xdmf.hpp): the XML text, written through a
// temporary file in the same folder.
#include "xdmf.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "erodem/error.hpp"
#include "erodem/io/results.hpp"

namespace erodem::io {

namespace {

namespace fs = std::filesystem;

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// Writes `text` to `path` through a temporary file in the same folder.
void write_text_file(const std::string& path, const std::string& text) {
  const std::string tmp = partial_path(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(ExitCode::cant_create, tmp + ": cannot create: " + std::strerror(errno));
    out << text;
    out.flush();
    if (!out) throw Error(ExitCode::io, tmp + ": writing failed");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(ExitCode::io, path + ": cannot rename into place: " + ec.message());
  }
}

}  // namespace

void write_xdmf(const std::string& path, const Grid& grid, const std::string& xname,
                const std::string& yname, const std::vector<double>& times,
                const std::vector<FieldInfo>& infos) {
  const std::string h5name = fs::path(path).filename().string();
  const std::size_t nt = times.size();
  std::string xmf = fmt::format(
      "<?xml version=\"1.0\" ?>\n"
      "<!-- erodem results: open this file in ParaView (XDMF reader); data in {0} -->\n"
      "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
      "  <Domain>\n"
      "    <Grid Name=\"erodem\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
      xml_escape(h5name));
  for (std::size_t k = 0; k < nt; ++k) {
    xmf += fmt::format(
        "      <Grid Name=\"t{0}\" GridType=\"Uniform\">\n"
        "        <Time Value=\"{1:.17g}\"/>\n"
        "        <Topology TopologyType=\"2DRectMesh\" Dimensions=\"{2} {3}\"/>\n"
        "        <Geometry GeometryType=\"VXVY\">\n"
        "          <DataItem Dimensions=\"{3}\" NumberType=\"Float\" Precision=\"8\" "
        "Format=\"HDF\">{4}:/{5}</DataItem>\n"
        "          <DataItem Dimensions=\"{2}\" NumberType=\"Float\" Precision=\"8\" "
        "Format=\"HDF\">{4}:/{6}</DataItem>\n"
        "        </Geometry>\n",
        k, times[k], grid.ny, grid.nx, xml_escape(h5name), xname, yname);
    for (const auto& info : infos)
      xmf += fmt::format(
          "        <Attribute Name=\"{0}\" AttributeType=\"Scalar\" Center=\"Node\">\n"
          "          <DataItem ItemType=\"HyperSlab\" Dimensions=\"{1} {2}\" "
          "Type=\"HyperSlab\">\n"
          "            <DataItem Dimensions=\"3 3\" Format=\"XML\">{3} 0 0 1 1 1 1 {1} "
          "{2}</DataItem>\n"
          "            <DataItem Dimensions=\"{4} {1} {2}\" NumberType=\"Float\" "
          "Precision=\"4\" Format=\"HDF\">{5}:/{0}</DataItem>\n"
          "          </DataItem>\n"
          "        </Attribute>\n",
          info.name, grid.ny, grid.nx, k, nt, xml_escape(h5name));
    xmf += "      </Grid>\n";
  }
  xmf += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  write_text_file(xdmf_path(path), xmf);
}

}  // namespace erodem::io
