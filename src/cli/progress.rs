//! The progress bar: the library's [`Progress`] events drawn with indicatif on stderr (hidden
//! under `--quiet` and when stderr is not a terminal).

use placewords::experiment::{Progress, ProgressSink};
use std::sync::Mutex;

/// A sink drawing one bar per stage, or nothing when `quiet`.
pub fn bar(quiet: bool) -> ProgressSink {
    if quiet {
        return ProgressSink::none();
    }
    let current: Mutex<Option<indicatif::ProgressBar>> = Mutex::new(None);
    ProgressSink::new(move |event| {
        let mut current = current.lock().unwrap_or_else(|e| e.into_inner());
        match event {
            Progress::Start { stage, steps } => {
                let bar = indicatif::ProgressBar::with_draw_target(
                    Some(steps),
                    indicatif::ProgressDrawTarget::stderr(),
                );
                bar.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{prefix:>12} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta}) {msg}",
                    )
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                    .progress_chars("=> "),
                );
                bar.set_prefix(stage.to_string());
                if let Some(old) = current.replace(bar) {
                    old.finish_and_clear();
                }
            }
            Progress::Step => {
                if let Some(bar) = current.as_ref() {
                    bar.inc(1);
                }
            }
            Progress::Status(text) => {
                if let Some(bar) = current.as_ref() {
                    bar.set_message(text.to_string());
                }
            }
            Progress::Done => {
                if let Some(bar) = current.take() {
                    bar.finish_and_clear();
                }
            }
        }
    })
}
