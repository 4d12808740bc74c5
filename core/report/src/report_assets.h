// Texts embedded into vc_report at build time by cmake/EmbedText.cmake (core/CMakeLists.txt), for
// report.html to inline. Each returns the file's text verbatim; none contains "</script",
// "</style" or "<!--" (the build checks). Internal to vc_report.
#pragma once

#include <string>

namespace vc::report_assets {

std::string ThreeJs();          // three.min.js, r111 (Debian libjs-three), defines the global THREE
std::string OrbitControlsJs();  // examples/js/controls/OrbitControls.js: THREE.OrbitControls
std::string ReportPageJs();     // core/report/src/report_page.js: the page's script
std::string ReportPageCss();    // core/report/src/report_page.css: the page's style

}  // namespace vc::report_assets
