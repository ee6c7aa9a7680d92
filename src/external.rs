//! A recognizer in any language: a program the harness starts and talks to over its standard
//! input and output, one JSON object per line (protocol version [`PROTOCOL_VERSION`], specified
//! in `docs/plugin.md`).
//!
//! The harness writes a `hello`, then per run a `start_run`, per frame a `frame` (its id, run,
//! odometric pose and scan) and at the end a `finish`; the program answers each line with one
//! line: its own `hello`, or `{"matches": [...]}` (for a frame also `"observe": false` when the
//! frame is not one of its observations). A match names frames the program observed earlier:
//! `{"pairs": [[query_frame, past_frame], ...], "direction": "same", "score": 0.9}`.
//!
//! Every way a program can go wrong — it cannot be started, exits, stays silent past the
//! timeout, prints a line that is not a reply, speaks another protocol version, or names a frame
//! it did not observe — ends the recognition with a [`ExternalError`] that names the program and
//! the line it printed ([`PlaceRecognizer::failure`]); the harness then writes nothing.

use crate::geom::OdomPose;
use crate::place::{Direction, FrameId, Match, ObsId, Observation, PlaceRecognizer, push_pair};
use crate::scan::Scan;
use crate::spec::evaluation::{is_builtin_subject_name, is_subject_name};
use serde::Deserialize;
use std::collections::HashMap;
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The protocol version this harness speaks; a program must answer `hello` with the same.
pub const PROTOCOL_VERSION: u32 = 1;

/// Default time a program may take to answer one line, seconds.
pub const DEFAULT_TIMEOUT_S: f64 = 30.0;

/// Lines of the program's standard error kept for an error message.
const STDERR_LINES: usize = 8;

/// An external subject as the command line or a scenario names it: `NAME=exec:COMMAND`.
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalSpec {
    /// The subject's name in reports, tables and `[expect]`.
    pub name: String,
    /// The command line, run by `sh -c` (so it may hold arguments and quotes).
    pub command: String,
    /// Time the program may take to answer one line, seconds. Default [`DEFAULT_TIMEOUT_S`].
    pub timeout_s: f64,
    /// The folder the command runs in, so relative paths in it resolve there: a scenario's
    /// folder for its `[[subjects]]`. `None` (a `--recognizer` flag): the current folder.
    pub dir: Option<std::path::PathBuf>,
    /// Where the subject was declared: `Some(file)` for a scenario's `[[subjects]]` entry
    /// (the scenario reproduces it), `None` for a `--recognizer` flag.
    pub declared_in: Option<String>,
}

impl ExternalSpec {
    /// Parses `NAME=exec:COMMAND` (the `--recognizer` flag's value).
    pub fn parse(text: &str) -> Result<Self, String> {
        let Some((name, rest)) = text.split_once('=') else {
            return Err(format!(
                "`{text}`: write NAME=exec:COMMAND, e.g. `mine=exec:python3 my_recognizer.py`"
            ));
        };
        let name = name.trim();
        if !is_subject_name(name) {
            return Err(format!(
                "`{name}` cannot name a subject: use letters, digits, `-` and `_`"
            ));
        }
        if is_builtin_subject_name(name) {
            return Err(format!(
                "`{name}` is the name of a built-in subject; choose another name"
            ));
        }
        let Some(command) = rest.strip_prefix("exec:") else {
            return Err(format!(
                "`{rest}` after `{name}=`: only `exec:COMMAND` is supported, e.g. \
                 `{name}=exec:python3 my_recognizer.py`"
            ));
        };
        if command.trim().is_empty() {
            return Err(format!("`{name}=exec:` names no command"));
        }
        Ok(ExternalSpec::new(name, command))
    }

    /// A subject `name` running `command` from the current folder, with the default timeout.
    pub fn new(name: &str, command: &str) -> Self {
        ExternalSpec {
            name: name.to_string(),
            command: command.to_string(),
            timeout_s: DEFAULT_TIMEOUT_S,
            dir: None,
            declared_in: None,
        }
    }

    /// `command` followed by `args`, each quoted for `sh` so it reaches the program as one
    /// argument (a `[[subjects]]` entry's `args`).
    pub fn command_with_args(command: &str, args: &[String]) -> Result<String, String> {
        let mut out = command.to_string();
        for a in args {
            let quoted = shlex::try_quote(a)
                .map_err(|e| format!("argument `{}` cannot be passed: {e}", a.escape_debug()))?;
            out.push(' ');
            out.push_str(&quoted);
        }
        Ok(out)
    }
}

/// The command-line flags that give `specs` again, quoted for a shell: one `--recognizer
/// NAME=exec:COMMAND` per subject a flag gave (a scenario's `[[subjects]]` come with the
/// scenario) and `--recognizer-timeout-s` when it was not the default. What a command
/// reproducing a seed needs; empty when no flag gave a subject.
pub fn reproduce_flags(specs: &[ExternalSpec]) -> String {
    let flagged: Vec<&ExternalSpec> = specs.iter().filter(|s| s.declared_in.is_none()).collect();
    let mut out: Vec<String> = flagged
        .iter()
        .map(|s| {
            let value = format!("{}=exec:{}", s.name, s.command);
            let quoted = shlex::try_quote(&value).map_or(value.clone(), |q| q.into_owned());
            format!("--recognizer {quoted}")
        })
        .collect();
    if let Some(s) = flagged.iter().find(|s| s.timeout_s != DEFAULT_TIMEOUT_S) {
        out.push(format!("--recognizer-timeout-s {}", s.timeout_s));
    }
    out.join(" ")
}

/// Why an external recognizer failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("external recognizer `{name}` (`{command}`): {what}")]
pub struct ExternalError {
    pub name: String,
    pub command: String,
    /// What went wrong, with the line the program printed where there is one.
    pub what: String,
}

/// One line the program printed (or the end of its output).
enum Line {
    Text(String),
    Closed,
}

/// A reply to `hello`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HelloReply {
    #[serde(rename = "type")]
    kind: String,
    protocol: u32,
    #[serde(default)]
    #[allow(dead_code)] // read for the program's own log; the harness names it by its flag
    name: Option<String>,
}

/// A reply to `start_run`, `frame` or `finish`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Reply {
    #[serde(default = "yes")]
    observe: bool,
    #[serde(default)]
    matches: Vec<MatchLine>,
}

fn yes() -> bool {
    true
}

/// A match as the program writes it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MatchLine {
    pairs: Vec<(FrameId, FrameId)>,
    #[serde(default)]
    direction: Direction,
    #[serde(default = "one")]
    score: f64,
}

fn one() -> f64 {
    1.0
}

/// A recognizer run as a child process (see the module doc).
pub struct ExternalRecognizer {
    spec: ExternalSpec,
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<Line>,
    stderr: Arc<Mutex<Vec<String>>>,
    /// Lines the program printed so far (the number of the next one, less one).
    printed: usize,
    observations: Vec<Observation>,
    by_frame: HashMap<FrameId, ObsId>,
    run: Option<usize>,
    travel_m: f64,
    last_odom: Option<OdomPose>,
    failure: Option<ExternalError>,
}

impl ExternalRecognizer {
    /// Starts the program and exchanges `hello`.
    pub fn start(spec: &ExternalSpec) -> Result<Self, ExternalError> {
        let fail = |what: String| ExternalError {
            name: spec.name.clone(),
            command: spec.command.clone(),
            what,
        };
        let mut command = Command::new("sh");
        if let Some(dir) = &spec.dir {
            command.current_dir(dir);
        }
        // Its own process group, so stopping it stops what `sh -c` started too (a program run by
        // the shell outlived a kill of the shell alone, spinning on after the run).
        std::os::unix::process::CommandExt::process_group(&mut command, 0);
        let mut child = command
            .arg("-c")
            .arg(&spec.command)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| fail(format!("cannot be started: {e}")))?;
        let stdout = child.stdout.take().expect("piped");
        let stderr_pipe = child.stderr.take().expect("piped");
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                match line {
                    Ok(l) => {
                        if tx.send(Line::Text(l)).is_err() {
                            return;
                        }
                    }
                    Err(_) => break,
                }
            }
            let _ = tx.send(Line::Closed);
        });
        let stderr = Arc::new(Mutex::new(Vec::new()));
        let kept = stderr.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr_pipe).lines().map_while(Result::ok) {
                let mut k = kept.lock().expect("stderr lines");
                k.push(line);
                if k.len() > STDERR_LINES {
                    k.remove(0);
                }
            }
        });
        let stdin = child.stdin.take();
        let mut rec = ExternalRecognizer {
            spec: spec.clone(),
            child,
            stdin,
            lines,
            stderr,
            printed: 0,
            observations: Vec::new(),
            by_frame: HashMap::new(),
            run: None,
            travel_m: 0.0,
            last_odom: None,
            failure: None,
        };
        let hello = serde_json::json!({"type": "hello", "protocol": PROTOCOL_VERSION});
        let line = rec.ask(&hello.to_string())?;
        let reply: HelloReply = serde_json::from_str(&line).map_err(|e| {
            rec.error(format!(
                "line {} is not a hello reply ({e}): `{}`; answer with \
                 {{\"type\": \"hello\", \"protocol\": {PROTOCOL_VERSION}}}",
                rec.printed,
                clip(&line)
            ))
        })?;
        if reply.kind != "hello" || reply.protocol != PROTOCOL_VERSION {
            return Err(rec.error(format!(
                "line {} answers hello with type `{}`, protocol {}; this harness speaks \
                 protocol {PROTOCOL_VERSION}",
                rec.printed, reply.kind, reply.protocol
            )));
        }
        Ok(rec)
    }

    fn error(&self, what: String) -> ExternalError {
        let stderr = self.stderr.lock().map(|l| l.clone()).unwrap_or_default();
        let what = if stderr.is_empty() {
            what
        } else {
            format!(
                "{what}\n  its last standard error lines:\n    {}",
                stderr.join("\n    ")
            )
        };
        ExternalError {
            name: self.spec.name.clone(),
            command: self.spec.command.clone(),
            what,
        }
    }

    /// Writes `request` as one line and waits for the program's one-line answer.
    fn ask(&mut self, request: &str) -> Result<String, ExternalError> {
        let written = match self.stdin.as_mut() {
            Some(w) => writeln!(w, "{request}").and_then(|()| w.flush()),
            None => Ok(()),
        };
        let timeout = Duration::from_secs_f64(self.spec.timeout_s.max(0.001));
        match self.lines.recv_timeout(timeout) {
            Ok(Line::Text(l)) => {
                self.printed += 1;
                Ok(l)
            }
            Ok(Line::Closed) | Err(RecvTimeoutError::Disconnected) => {
                Err(self.closed(request, written.is_ok()))
            }
            Err(RecvTimeoutError::Timeout) => {
                self.stop();
                Err(self.error(format!(
                    "no answer within {} s to `{}` (after {} line(s)); it was stopped",
                    self.spec.timeout_s,
                    clip(request),
                    self.printed
                )))
            }
        }
    }

    /// Stops the program and everything it started: the process group `start` gave it
    /// (the `sh -c` and what it runs), then the shell itself if the group is already gone.
    fn stop(&mut self) {
        let group = rustix::process::Pid::from_child(&self.child);
        let _ = rustix::process::kill_process_group(group, rustix::process::Signal::KILL);
        let _ = self.child.kill();
    }

    /// The error for a recognizer that closed its output while `request` (`read`: written to
    /// it) waited for an answer: its exit status when it has one.
    fn closed(&mut self, request: &str, read: bool) -> ExternalError {
        // Give the exit status a moment to arrive.
        std::thread::sleep(Duration::from_millis(50));
        let status = match self.child.try_wait() {
            Ok(Some(s)) => format!("exited ({s})"),
            _ => "closed its standard output".to_string(),
        };
        let during = if read {
            ""
        } else {
            " before it read its input"
        };
        self.error(format!(
            "{status}{during} after printing {} line(s), while the harness waited for \
             the answer to `{}`",
            self.printed,
            clip(request)
        ))
    }

    /// Sends `request` and turns the answer into matches; a failure is kept (and ends every
    /// later exchange), since the trait's methods cannot return it.
    fn exchange(&mut self, request: &str, frame: Option<(FrameId, OdomPose)>) -> Vec<Match> {
        if self.failure.is_some() {
            return Vec::new();
        }
        match self.try_exchange(request, frame) {
            Ok(m) => m,
            Err(e) => {
                self.stop();
                self.failure = Some(e);
                Vec::new()
            }
        }
    }

    fn try_exchange(
        &mut self,
        request: &str,
        frame: Option<(FrameId, OdomPose)>,
    ) -> Result<Vec<Match>, ExternalError> {
        let line = self.ask(request)?;
        let reply: Reply = serde_json::from_str(&line).map_err(|e| {
            self.error(format!(
                "line {} is not a reply ({e}): `{}`; answer each line with e.g. \
                 {{\"matches\": []}}",
                self.printed,
                clip(&line)
            ))
        })?;
        if let Some((frame_id, odom)) = frame
            && reply.observe
        {
            let id = self.observations.len();
            let run = self.run.unwrap_or(0);
            self.observations
                .push(Observation::new(id, run, frame_id, odom, self.travel_m));
            self.by_frame.insert(frame_id, id);
        }
        let mut out = Vec::new();
        for m in reply.matches {
            let mut runs = Vec::new();
            for (q, p) in m.pairs {
                let obs = |f: FrameId| self.by_frame.get(&f).copied();
                let (Some(qo), Some(po)) = (obs(q), obs(p)) else {
                    let unknown = if obs(q).is_none() { q } else { p };
                    return Err(self.error(format!(
                        "line {} names frame {unknown}, which it has not observed (a match \
                         pairs frames it answered with \"observe\" true, or left it out, earlier \
                         or now): `{}`",
                        self.printed,
                        clip(&line)
                    )));
                };
                if !m.score.is_finite() {
                    return Err(self.error(format!(
                        "line {} gives a match the score {}; scores are finite numbers",
                        self.printed, m.score
                    )));
                }
                let step = match m.direction {
                    Direction::Same => 1,
                    Direction::Opposite => -1,
                };
                push_pair(&mut runs, qo, po, step);
            }
            if !runs.is_empty() {
                out.push(Match::new(runs, m.direction, m.score));
            }
        }
        Ok(out)
    }
}

/// `text` cut to 200 characters for a message.
fn clip(text: &str) -> String {
    let mut s: String = text.chars().take(200).collect();
    if s.len() < text.len() {
        s.push('…');
    }
    s
}

/// The `frame` request for frame `frame_id` of run `run`: its odometry and scan (a range
/// without a return as `null`).
fn frame_request(frame_id: FrameId, run: usize, odom: OdomPose, scan: &Scan) -> String {
    let ranges: Vec<serde_json::Value> = scan
        .ranges_m
        .iter()
        .map(|&r| {
            if r.is_finite() {
                r.into()
            } else {
                serde_json::Value::Null
            }
        })
        .collect();
    serde_json::json!({
        "type": "frame",
        "frame": frame_id,
        "run": run,
        "odom": {"x_m": odom.0.x, "y_m": odom.0.y, "theta_rad": odom.0.theta},
        "scan": {
            "time_s": scan.time_s,
            "start_angle_rad": scan.layout.start_angle_rad,
            "step_rad": scan.layout.step_rad,
            "max_range_m": scan.layout.max_range_m,
            "ranges_m": ranges,
        },
    })
    .to_string()
}

impl PlaceRecognizer for ExternalRecognizer {
    fn start_run(&mut self) -> Vec<Match> {
        let run = self.run.map_or(0, |r| r + 1);
        self.run = Some(run);
        self.last_odom = None;
        let request = serde_json::json!({"type": "start_run", "run": run}).to_string();
        self.exchange(&request, None)
    }

    fn push(&mut self, frame_id: FrameId, odom: OdomPose, scan: &Scan) -> Vec<Match> {
        if self.failure.is_some() {
            return Vec::new();
        }
        if let Some(last) = self.last_odom {
            self.travel_m += last.0.distance(&odom.0);
        }
        self.last_odom = Some(odom);
        let request = frame_request(frame_id, self.run.unwrap_or(0), odom, scan);
        self.exchange(&request, Some((frame_id, odom)))
    }

    fn finish(&mut self) -> Vec<Match> {
        let request = serde_json::json!({"type": "finish"}).to_string();
        let out = self.exchange(&request, None);
        self.stdin = None;
        out
    }

    fn observations(&self) -> &[Observation] {
        &self.observations
    }

    fn name(&self) -> String {
        self.spec.name.clone()
    }

    fn failure(&self) -> Option<String> {
        self.failure.as_ref().map(ToString::to_string)
    }

    fn runs_out_of_process(&self) -> bool {
        true
    }
}

impl Drop for ExternalRecognizer {
    fn drop(&mut self) {
        self.stdin = None;
        // A program that does not end on its own once its input closes is stopped.
        for _ in 0..20 {
            if matches!(self.child.try_wait(), Ok(Some(_))) {
                return;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        self.stop();
        let _ = self.child.wait();
    }
}
