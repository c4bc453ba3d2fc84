#pragma once
// The --screenshot of nadir-plot and nadir-viewer: the shown window saved as PNG
// once it has had time to lay itself out (and, live, to listen), then the program
// ends.

#include <functional>
#include <string>

class QWidget;

namespace nadir::gui {

// After wait_s seconds of the event loop, saves window to png_path and exits the
// application with 0, after report (what was shown, for scripts) if given; if
// the file cannot be written, says so on stderr as `program: cannot write PATH`
// and exits with 1. Call before QApplication::exec().
void screenshotAfter(QWidget& window, double wait_s, const std::string& png_path,
                     const std::string& program, std::function<void()> report = {});

// The same, as soon as ready() holds (asked every 100 ms), and after wait_s at
// the most: a script waits for a condition, not for a time a loaded machine
// may not keep.
void screenshotWhen(QWidget& window, std::function<bool()> ready, double wait_s,
                    const std::string& png_path, const std::string& program,
                    std::function<void()> report = {});

}  // namespace nadir::gui
