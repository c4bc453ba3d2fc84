#pragma once
// GDAL for the terrain readers (not for other libraries: it keeps GDAL's
// headers inside terrain/).

#include <string>

namespace nadir::terrain {

// Registers GDAL's drivers once and turns off its side files (.aux.xml), so
// reading a raster never writes beside it. Safe from any thread.
void initGdal();

// While alive, collects the errors GDAL and PROJ report on this thread
// instead of printing them.
class GdalErrors {
 public:
  GdalErrors();
  ~GdalErrors();
  GdalErrors(const GdalErrors&) = delete;
  GdalErrors& operator=(const GdalErrors&) = delete;

  // " (GDAL: first message; second ...)" or "" if nothing was said.
  std::string said() const;
  const std::string& messages() const { return messages_; }

 private:
  std::string messages_;
};

}  // namespace nadir::terrain
