#include "terrain/gdal_support.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>

#include <mutex>

namespace nadir::terrain {
namespace {

void collect(CPLErr level, CPLErrorNum, const char* message) {
  if (level != CE_Failure && level != CE_Fatal) return;
  auto* messages = static_cast<std::string*>(CPLGetErrorHandlerUserData());
  if (messages == nullptr || message == nullptr) return;
  if (messages->size() > 2000) return;  // a broken file can repeat itself
  if (!messages->empty()) *messages += "; ";
  *messages += message;
}

}  // namespace

void initGdal() {
  static std::once_flag once;
  std::call_once(once, [] {
    CPLSetConfigOption("GDAL_PAM_ENABLED", "NO");
    GDALAllRegister();
  });
}

GdalErrors::GdalErrors() {
  initGdal();
  CPLPushErrorHandlerEx(collect, &messages_);
}

GdalErrors::~GdalErrors() { CPLPopErrorHandler(); }

std::string GdalErrors::said() const {
  return messages_.empty() ? std::string() : " (GDAL: " + messages_ + ")";
}

}  // namespace nadir::terrain
