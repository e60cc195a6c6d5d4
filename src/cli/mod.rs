//! What every tool's command line shares: the parser's errors as one line naming the flag,
//! negative numbers read as values, flags checked even where another flag makes them unused,
//! and a run interrupted by SIGINT or SIGTERM that removes what it staged before it exits.
//!
//! ```text
//! let parsed = hairmesh::cli::parse::<Args>("crowd");   // exits 2 with one line on a bad flag
//! parsed.unused_unless("volume_band", args.volumes, "--volumes is off")?;
//! hairmesh::cli::clean_up_on_signals("crowd");
//! ```

pub mod flags;
pub use flags::{DeviceFlags, LodFlags, LookFlags};

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::parser::ValueSource;
use clap::{ArgMatches, Command, Parser};

/// Parsed arguments and what the user gave on the command line.
pub struct Parsed<T> {
    /// The arguments.
    pub args: T,
    matches: ArgMatches,
    command: Command,
}

/// Every argument that takes a value reads `-5` as its value (a range check then names the
/// flag), in every subcommand.
fn negative_numbers_as_values(cmd: Command) -> Command {
    cmd.mut_args(|a| {
        if a.get_action().takes_values() {
            a.allow_negative_numbers(true)
        } else {
            a
        }
    })
    .mut_subcommands(negative_numbers_as_values)
}

/// A context value as text (lists joined by ", ").
fn context_text(value: &ContextValue) -> String {
    match value {
        ContextValue::Strings(list) => list.join(", "),
        other => other.to_string(),
    }
}

/// One line for a clap error: the flag at fault, the value and why, with the possible values
/// or a suggestion where clap has one.
pub fn one_line(err: &clap::Error) -> String {
    let get = |kind| err.get(kind).map(context_text);
    let mut line = match err.kind() {
        ErrorKind::MissingRequiredArgument => format!(
            "missing {} (see --help)",
            get(ContextKind::InvalidArg).unwrap_or_else(|| "a required argument".into())
        ),
        ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            "a subcommand is required (see --help)".to_string()
        }
        _ => {
            let rendered = err.render().to_string();
            let first = rendered
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("");
            first.trim_start_matches("error: ").trim().to_string()
        }
    };
    if let Some(valid) = get(ContextKind::ValidValue)
        && !valid.is_empty()
    {
        line.push_str(&format!("; possible values: {valid}"));
    }
    let suggestion = get(ContextKind::SuggestedArg)
        .or_else(|| get(ContextKind::SuggestedSubcommand))
        .or_else(|| get(ContextKind::SuggestedValue));
    if let Some(s) = suggestion {
        line.push_str(&format!("; did you mean '{s}'?"));
    }
    line
}

/// Parse `args` (the first is the program name) as `T`; a parser error is one line.
pub fn try_parse_from<T: Parser, I, S>(args: I) -> Result<Parsed<T>, clap::Error>
where
    I: IntoIterator<Item = S>,
    S: Into<std::ffi::OsString> + Clone,
{
    let command = negative_numbers_as_values(T::command());
    let matches = command.clone().try_get_matches_from(args)?;
    let args = T::from_arg_matches(&matches)?;
    Ok(Parsed {
        args,
        matches,
        command,
    })
}

/// Parse the process's arguments as `T`. `--help` and `--version` print and exit 0; any other
/// parser error prints `tool: <one line>` and exits 2.
pub fn parse<T: Parser>(tool: &str) -> Parsed<T> {
    match try_parse_from::<T, _, _>(std::env::args_os()) {
        Ok(p) => p,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            let _ = e.print();
            std::process::exit(0)
        }
        Err(e) => crate::fsutil::exit_with_error(tool, &one_line(&e), 2),
    }
}

impl<T> Parsed<T> {
    /// The matches of the subcommand that ran (the top level when there is none).
    fn leaf(&self) -> (&ArgMatches, &Command) {
        let (mut m, mut c) = (&self.matches, &self.command);
        while let Some((name, sub)) = m.subcommand() {
            match c.find_subcommand(name) {
                Some(sc) => (m, c) = (sub, sc),
                None => break,
            }
        }
        (m, c)
    }

    /// Whether the flag with field name `id` was given on the command line (not a default).
    pub fn given(&self, id: &str) -> bool {
        let (m, _) = self.leaf();
        m.try_get_raw(id).is_ok_and(|v| v.is_some())
            && m.value_source(id) == Some(ValueSource::CommandLine)
    }

    /// The flag of field `id` as a user writes it (`--volume-band`).
    pub fn flag(&self, id: &str) -> String {
        let (_, c) = self.leaf();
        c.get_arguments()
            .find(|a| a.get_id() == id)
            .and_then(|a| a.get_long().map(|l| format!("--{l}")))
            .unwrap_or_else(|| id.replace('_', "-"))
    }

    /// Refuse flag `id` when it was given but has no effect: `used` is false, `why` says
    /// which other flag turned its feature off.
    pub fn unused_unless(&self, id: &str, used: bool, why: &str) -> Result<(), String> {
        if self.given(id) && !used {
            return Err(format!("{} has no effect: {why}", self.flag(id)));
        }
        Ok(())
    }
}

/// Install the SIGINT / SIGTERM / SIGHUP handler of a tool: the first signal removes every
/// file and folder this process staged and has not yet published (`fsutil`'s staging list; a
/// publish in progress finishes first, so outputs stay all from one run or as they were), prints
/// one line and exits 130 (SIGINT) or 128 + the signal; a second signal ends the process at once.
pub fn clean_up_on_signals(tool: &'static str) {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let signals = [SIGINT, SIGTERM, SIGHUP];
    let second = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    for s in signals {
        // The second signal exits at once (status 1) without waiting for the cleanup.
        let _ = signal_hook::flag::register_conditional_shutdown(s, 1, second.clone());
        let _ = signal_hook::flag::register(s, second.clone());
    }
    let Ok(mut iter) = signal_hook::iterator::Signals::new(signals) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = iter.forever().next() {
            let name = match signal {
                SIGINT => "SIGINT",
                SIGTERM => "SIGTERM",
                _ => "SIGHUP",
            };
            crate::fsutil::remove_staged_then(|removed| {
                use std::io::Write as _;
                let _ = std::io::stdout().flush();
                let _ = writeln!(
                    std::io::stderr(),
                    "{tool}: interrupted by {name}; removed {removed} staged path(s), outputs left as they were"
                );
                // `_exit`: no atexit handlers (the GPU driver's) run beside the main thread.
                signal_hook::low_level::exit(128 + signal)
            })
        }
    });
}
