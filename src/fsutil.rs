//! Files in and out, with one policy for every tool.
//!
//! **Inputs** are read only when they are regular files (a FIFO without a writer would block,
//! a device could stream forever) and no larger than a stated cap.
//!
//! **Outputs** ([`OutputPath`]) are checked before any work: an output that is one of the
//! inputs (the same file, also through links) is refused; a symbolic link, folder, FIFO,
//! socket or block device is refused; a character device (`/dev/null`) is written in place;
//! a regular file or a new path is written atomically (temporary file next to it, synced,
//! renamed), so a failed run never leaves a half-written file. Tools write only after their
//! work (and the GPU frame's validation) succeeded. An output's folders that do not exist yet
//! are made when it is written (as `mkdir -p` would) and removed again if the write fails.
//!
//! **Staged paths** (temporary files, staging folders, folders made for outputs) are listed
//! until they are published, so an interrupted run removes them ([`remove_staged_then`], called
//! by `cli`'s signal handler). **Publishing** (the renames that put a run's outputs in place)
//! holds this process's staging list and an exclusive lock (`flock`) on each output folder:
//! two runs writing the same outputs publish one after the other, never interleaved, so the
//! outputs are all from one run.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use crate::error::{HairError, Result};

/// Largest OBJ or baked `.hmb` file read, in bytes.
pub const MAX_MESH_FILE_BYTES: u64 = 512 << 20;
/// Largest style or scene TOML read, in bytes.
pub const MAX_TEXT_FILE_BYTES: u64 = 1 << 20;

/// Read `path` whole if it is a regular file of at most `max_bytes`.
pub fn read_input(path: &Path, max_bytes: u64) -> Result<Vec<u8>> {
    let meta = std::fs::metadata(path).map_err(|e| HairError::io(path, e))?;
    if !meta.is_file() {
        return Err(HairError::invalid(
            path.display().to_string(),
            "not a regular file (folders, FIFOs and devices are not read)",
        ));
    }
    let too_big = || {
        HairError::invalid(
            path.display().to_string(),
            format!("larger than the {max_bytes}-byte limit for this kind of file"),
        )
    };
    if meta.len() > max_bytes {
        return Err(too_big());
    }
    let file = std::fs::File::open(path).map_err(|e| HairError::io(path, e))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| HairError::io(path, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big());
    }
    Ok(bytes)
}

/// [`read_input`] as UTF-8 text.
pub fn read_text_input(path: &Path, max_bytes: u64) -> Result<String> {
    String::from_utf8(read_input(path, max_bytes)?).map_err(|e| {
        HairError::invalid(
            path.display().to_string(),
            format!("not UTF-8 text: {}", e.utf8_error()),
        )
    })
}

/// How an output is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OutputKind {
    /// New or regular file: atomically (temporary file + rename).
    Atomic,
    /// Character device such as `/dev/null`: in place.
    Device,
}

/// A checked output path ([`OutputPath::check`]); write it with [`OutputPath::write`].
#[derive(Clone, Debug)]
pub struct OutputPath {
    path: PathBuf,
    kind: OutputKind,
    /// Folders above the path that do not exist yet, outermost first: made when it is written.
    missing: Vec<PathBuf>,
}

/// Whether `e` says the path does not exist (or lies below a file: the folder check above it
/// names that file).
fn absent(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
    )
}

/// The folders of `folder` and above that do not exist, outermost first, up to the nearest
/// one that does; refused when that one is not a folder. `what` names the output.
fn missing_folders(folder: &Path, what: &str) -> Result<Vec<PathBuf>> {
    let mut missing = Vec::new();
    let mut at = folder;
    loop {
        match std::fs::metadata(at) {
            Ok(m) if m.is_dir() => break,
            Ok(_) => {
                return Err(HairError::invalid(
                    what,
                    format!("{} is not a folder", at.display()),
                ));
            }
            Err(e) if absent(&e) => {
                missing.push(at.to_path_buf());
                match at.parent() {
                    Some(p) if !p.as_os_str().is_empty() => at = p,
                    _ => break,
                }
            }
            Err(e) => return Err(HairError::io(at, e)),
        }
    }
    missing.reverse();
    Ok(missing)
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    false
}

impl OutputPath {
    /// Check `path` as an output of a run that reads `inputs` (missing inputs are ignored here;
    /// reading them reports them).
    pub fn check(path: &Path, inputs: &[&Path]) -> Result<Self> {
        let name = path.display().to_string();
        let refuse = |why: &str| Err(HairError::invalid(&name, format!("output {why}")));
        let kind = match std::fs::symlink_metadata(path) {
            Err(e) if absent(&e) => {
                if path.file_name().is_none() {
                    return refuse("is not a file path");
                }
                return Ok(OutputPath {
                    path: path.to_path_buf(),
                    kind: OutputKind::Atomic,
                    missing: missing_folders(parent_folder(path), &name)?,
                });
            }
            Err(e) => return Err(HairError::io(path, e)),
            Ok(m) if m.file_type().is_symlink() => {
                return refuse("is a symbolic link; give the path it points to");
            }
            Ok(m) if m.is_dir() => return refuse("is a folder"),
            Ok(m) if m.is_file() => OutputKind::Atomic,
            Ok(m) if is_char_device(&m) => OutputKind::Device,
            Ok(_) => return refuse("is a FIFO, socket or block device; not written"),
        };
        let out_meta = std::fs::metadata(path).map_err(|e| HairError::io(path, e))?;
        for input in inputs {
            if let Ok(m) = std::fs::metadata(input)
                && m.is_file()
                && same_file(&m, &out_meta)
            {
                return refuse(&format!(
                    "is the input {}; refusing to overwrite it",
                    input.display()
                ));
            }
        }
        Ok(OutputPath {
            path: path.to_path_buf(),
            kind,
            missing: Vec::new(),
        })
    }

    /// The path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Write `bytes` by the policy of this module.
    pub fn write(&self, bytes: &[u8]) -> Result<()> {
        match self.kind {
            OutputKind::Atomic => write_together(&[(self, bytes)]),
            OutputKind::Device => std::fs::OpenOptions::new()
                .write(true)
                .open(&self.path)
                .and_then(|mut f| f.write_all(bytes))
                .map_err(|e| HairError::io(&self.path, e)),
        }
    }
}

/// Every file one run of a tool reads and writes, checked together before any work: an
/// output may be none of the inputs (also those a run reads without naming them: the style
/// beside a mesh, the files a scene names, a `fit` head) and no two outputs may be the same
/// path (else one would silently replace the other).
#[derive(Default)]
pub struct RunFiles {
    inputs: Vec<PathBuf>,
    outputs: Vec<(PathBuf, PathBuf)>,
}

/// The folder `path` lies in (`.` for a bare file name).
fn parent_folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// `path` made absolute with its folder resolved (links included), for comparing outputs that
/// do not exist yet; unchanged where its folder cannot be resolved.
fn resolved(path: &Path) -> PathBuf {
    match (std::fs::canonicalize(parent_folder(path)), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

impl RunFiles {
    /// An empty plan.
    pub fn new() -> Self {
        Self::default()
    }

    /// Count `path` as read by this run (register every input before the first output).
    pub fn input(&mut self, path: &Path) -> &mut Self {
        self.inputs.push(path.to_path_buf());
        self
    }

    /// Count every path of `paths` as read by this run.
    pub fn inputs<'a>(&mut self, paths: impl IntoIterator<Item = &'a Path>) -> &mut Self {
        for p in paths {
            self.input(p);
        }
        self
    }

    /// Check `path` as an output ([`OutputPath::check`] against every input so far) that no
    /// earlier output of this run already is; `what` names it in the error (a flag).
    pub fn output(&mut self, path: &Path, what: &str) -> Result<OutputPath> {
        let inputs: Vec<&Path> = self.inputs.iter().map(PathBuf::as_path).collect();
        let out = OutputPath::check(path, &inputs)?;
        let key = resolved(path);
        if let Some((earlier, _)) = self.outputs.iter().find(|(_, k)| *k == key)
            && out.kind == OutputKind::Atomic
        {
            return Err(HairError::invalid(
                path.display().to_string(),
                format!(
                    "{what} is also this run's output {}; give each output its own path",
                    earlier.display()
                ),
            ));
        }
        self.outputs.push((path.to_path_buf(), key));
        Ok(out)
    }
}

/// A path this process staged and has not published.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Staged {
    /// A temporary file.
    File(PathBuf),
    /// A staging folder and everything in it.
    Tree(PathBuf),
    /// A folder made for an output: removed only while empty (another run may use it too).
    Folder(PathBuf),
}

impl Staged {
    fn remove(&self) {
        let _ = match self {
            Staged::File(p) => std::fs::remove_file(p),
            Staged::Tree(p) => std::fs::remove_dir_all(p),
            Staged::Folder(p) => std::fs::remove_dir(p),
        };
    }
}

/// Every path this process staged and has not published, in the order they were made.
static STAGED: Mutex<Vec<Staged>> = Mutex::new(Vec::new());

/// The staging list (a panic while it was held left it consistent: entries are whole).
fn staged_list() -> MutexGuard<'static, Vec<Staged>> {
    STAGED.lock().unwrap_or_else(|p| p.into_inner())
}

/// Add `entry` to the staging list.
fn track(entry: Staged) {
    staged_list().push(entry);
}

/// Remove and delete `entries` (newest first), and take them off the staging list.
fn discard(entries: &[Staged]) {
    let mut list = staged_list();
    for e in entries.iter().rev() {
        e.remove();
        list.retain(|x| x != e);
    }
}

/// Remove every path this process staged and has not published (newest first), then call
/// `then` with their number while still holding the list, so no publish starts or half-ends:
/// the signal handler's cleanup (`cli::clean_up_on_signals`), which exits in `then`.
pub fn remove_staged_then(then: impl FnOnce(usize) -> std::convert::Infallible) -> ! {
    let mut list = staged_list();
    let n = list.len();
    for e in list.drain(..).rev() {
        e.remove();
    }
    match then(n) {}
}

/// Make `folders` (outermost first), listing each as staged: an interrupted or failed run
/// removes them again (when empty).
fn make_folders(folders: &[PathBuf]) -> Result<Vec<Staged>> {
    let mut made = Vec::new();
    for f in folders {
        track(Staged::Folder(f.clone()));
        made.push(Staged::Folder(f.clone()));
        match std::fs::create_dir(f) {
            Ok(()) => {}
            // Another run made it meanwhile: not ours to remove.
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && f.is_dir() => {
                discard_entry(made.pop().as_ref());
            }
            Err(e) => {
                discard(&made);
                return Err(HairError::io(f, e));
            }
        }
    }
    Ok(made)
}

/// Take one entry off the staging list without removing its path.
fn discard_entry(entry: Option<&Staged>) {
    if let Some(e) = entry {
        let mut list = staged_list();
        if let Some(i) = list.iter().rposition(|x| x == e) {
            list.remove(i);
        }
    }
}

/// A publish in progress: this process's staging list (a signal's cleanup waits for it) and an
/// exclusive lock on every output folder (another run's publish waits for it).
struct Publish {
    list: MutexGuard<'static, Vec<Staged>>,
    _locks: Vec<std::fs::File>,
}

impl Publish {
    /// Lock the staging list, then `folders` (sorted, so two runs cannot deadlock).
    fn begin<'a>(folders: impl IntoIterator<Item = &'a Path>) -> Self {
        let list = staged_list();
        let mut keys: Vec<PathBuf> = folders
            .into_iter()
            .map(|f| std::fs::canonicalize(f).unwrap_or_else(|_| f.to_path_buf()))
            .collect();
        keys.sort();
        keys.dedup();
        let mut locks = Vec::new();
        for k in keys {
            // A folder that cannot be opened for reading, or a file system without locks
            // (some network and FUSE mounts), publishes unlocked: one run's outputs stay
            // all-or-none, only concurrent runs are not ordered there.
            if let Ok(f) = std::fs::File::open(&k)
                && f.lock().is_ok()
            {
                locks.push(f);
            }
        }
        Publish {
            list,
            _locks: locks,
        }
    }

    /// `entries` are published: off the staging list, left in place.
    fn keep(&mut self, entries: &[Staged]) {
        self.list.retain(|x| !entries.contains(x));
    }

    /// Tests: wait between two renames of a publish, so two runs' publishes would interleave
    /// without the lock (`HAIRMESH_TEST_PUBLISH_PAUSE_MS`).
    fn test_pause() {
        if let Some(ms) = std::env::var("HAIRMESH_TEST_PUBLISH_PAUSE_MS")
            .ok()
            .and_then(|v| v.parse::<u64>().ok())
        {
            std::thread::sleep(std::time::Duration::from_millis(ms.min(60_000)));
        }
    }
}

/// A folder of outputs written over a long run (frames) that appear only if the run succeeds:
/// every file's path is checked first ([`RunFiles::output`]), files go to a hidden staging
/// folder beside the target as they are made, and [`StagedFolder::publish`] moves them in at
/// the end. Dropped without publishing (an error, a panic) or interrupted (a signal), the
/// staging folder is removed, with the folders made for it: a failed run leaves the target as
/// it was, and creates nothing.
pub struct StagedFolder {
    target: PathBuf,
    staging: PathBuf,
    existed: bool,
    /// Folders above the target that do not exist yet, outermost first.
    missing: Vec<PathBuf>,
    /// What this run made so far (folders above, the staging folder), oldest first.
    made: Vec<Staged>,
    written: Vec<String>,
}

impl StagedFolder {
    /// Check folder `target` (existing, or new: its missing folders are made when the first
    /// file is written) and the files `names` in it as outputs of `files`' run; `what` names
    /// the folder in errors (a flag).
    pub fn check(
        target: &Path,
        names: &[String],
        files: &mut RunFiles,
        what: &str,
    ) -> Result<Self> {
        let name = format!("{what} {}", target.display());
        let existed = match std::fs::symlink_metadata(target) {
            Ok(m) if m.is_dir() => true,
            Ok(_) => return Err(HairError::invalid(name, "not a folder")),
            Err(e) if absent(&e) => false,
            Err(e) => return Err(HairError::io(target, e)),
        };
        let leaf = target
            .file_name()
            .ok_or_else(|| HairError::invalid(&name, "not a folder path"))?;
        let parent = parent_folder(target);
        let missing = if existed {
            Vec::new()
        } else {
            missing_folders(parent, &name)?
        };
        // Nothing lies in a folder that does not exist yet: only an existing one's entries
        // can be links, folders or inputs.
        if existed {
            for n in names {
                files.output(&target.join(n), what)?;
            }
        }
        let staging = parent.join(format!(
            ".{}.partial{}",
            leaf.to_string_lossy(),
            std::process::id()
        ));
        Ok(StagedFolder {
            target: target.to_path_buf(),
            staging,
            existed,
            missing,
            made: Vec::new(),
            written: Vec::new(),
        })
    }

    /// Write file `name` (one of the checked names) into the staging folder.
    pub fn write(&mut self, name: &str, bytes: &[u8]) -> Result<()> {
        self.ensure_staging()?;
        let path = self.staging.join(name);
        std::fs::write(&path, bytes).map_err(|e| HairError::io(&path, e))?;
        self.written.push(name.to_string());
        Ok(())
    }

    /// Make the missing folders and the staging folder on first use.
    fn ensure_staging(&mut self) -> Result<()> {
        if self.made.iter().any(|m| matches!(m, Staged::Tree(_))) {
            return Ok(());
        }
        self.made = make_folders(&std::mem::take(&mut self.missing))?;
        let tree = Staged::Tree(self.staging.clone());
        track(tree.clone());
        self.made.push(tree);
        std::fs::create_dir(&self.staging).map_err(|e| HairError::io(&self.staging, e))
    }

    /// Move every written file into the target folder (the whole staging folder when the
    /// target does not exist, also when another run made it after the check).
    pub fn publish(mut self) -> Result<()> {
        self.ensure_staging()?;
        let mut publish = Publish::begin([parent_folder(&self.target)]);
        if self.existed || self.target.is_dir() {
            for (k, n) in self.written.iter().enumerate() {
                if k == 1 {
                    Publish::test_pause();
                }
                let (from, to) = (self.staging.join(n), self.target.join(n));
                std::fs::rename(&from, &to).map_err(|e| HairError::io(&to, e))?;
            }
            let _ = std::fs::remove_dir(&self.staging);
        } else {
            std::fs::rename(&self.staging, &self.target)
                .map_err(|e| HairError::io(&self.target, e))?;
        }
        publish.keep(&std::mem::take(&mut self.made));
        Ok(())
    }
}

impl Drop for StagedFolder {
    fn drop(&mut self) {
        discard(&self.made);
    }
}

#[cfg(unix)]
fn is_char_device(m: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    m.file_type().is_char_device()
}

#[cfg(not(unix))]
fn is_char_device(_: &std::fs::Metadata) -> bool {
    false
}

/// Write `bytes` to `path` atomically: a temporary file in the same folder, synced, then renamed.
/// Tools go through [`OutputPath`], which decides when this is the right way to write.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let out = OutputPath {
        path: path.to_path_buf(),
        kind: OutputKind::Atomic,
        missing: Vec::new(),
    };
    write_together(&[(&out, bytes)])
}

/// Write `bytes` to a hidden temporary file beside `path` (synced, listed as staged), to be
/// renamed onto it.
fn stage(path: &Path, bytes: &[u8]) -> Result<Staged> {
    let dir = parent_folder(path);
    let file_name = path
        .file_name()
        .ok_or_else(|| HairError::invalid(path.display().to_string(), "not a file path"))?;
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        file_name.to_string_lossy(),
        std::process::id()
    ));
    let entry = Staged::File(tmp.clone());
    track(entry.clone());
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })();
    if let Err(e) = result {
        discard(std::slice::from_ref(&entry));
        return Err(HairError::io(path, e));
    }
    Ok(entry)
}

/// Write several outputs of one run all or none: their missing folders are made and every
/// file is staged (written and synced beside its path) before the first is renamed into place,
/// so a full disk or a failing write leaves no output of the run behind (and no folder it made);
/// the renames hold the output folders' locks. Devices (`/dev/null`) are written
/// last.
pub fn write_together(outputs: &[(&OutputPath, &[u8])]) -> Result<()> {
    let mut made: Vec<Staged> = Vec::new();
    let mut staged: Vec<(Staged, &Path)> = Vec::new();
    let fail = |made: &[Staged], staged: &[(Staged, &Path)], e| {
        let files: Vec<Staged> = staged.iter().map(|(s, _)| s.clone()).collect();
        discard(&files);
        discard(made);
        Err(e)
    };
    for (out, bytes) in outputs {
        if matches!(out.kind, OutputKind::Atomic) {
            let missing: Vec<PathBuf> = out
                .missing
                .iter()
                .filter(|f| !f.is_dir())
                .cloned()
                .collect();
            match make_folders(&missing) {
                Ok(m) => made.extend(m),
                Err(e) => return fail(&made, &staged, e),
            }
            match stage(&out.path, bytes) {
                Ok(tmp) => staged.push((tmp, &out.path)),
                Err(e) => return fail(&made, &staged, e),
            }
        }
    }
    let mut publish = Publish::begin(staged.iter().map(|(_, p)| parent_folder(p)));
    for (k, (tmp, path)) in staged.iter().enumerate() {
        if k == 1 {
            Publish::test_pause();
        }
        let Staged::File(from) = tmp else { continue };
        if let Err(e) = std::fs::rename(from, path) {
            drop(publish);
            return fail(&made, &staged[k..], HairError::io(*path, e));
        }
    }
    let files: Vec<Staged> = staged.into_iter().map(|(s, _)| s).collect();
    publish.keep(&files);
    publish.keep(&made);
    drop(publish);
    for (out, bytes) in outputs {
        if !matches!(out.kind, OutputKind::Atomic) {
            out.write(bytes)?;
        }
    }
    Ok(())
}

/// Encode RGBA8 pixels (`width x height`, top row first) as PNG bytes.
pub fn encode_png(name: &str, width: u32, height: u32, rgba: Vec<u8>) -> Result<Vec<u8>> {
    let img = image::RgbaImage::from_raw(width, height, rgba).ok_or_else(|| {
        HairError::invalid(name, format!("pixel data does not match {width}x{height}"))
    })?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| HairError::invalid(name, format!("PNG encoding: {e}")))?;
    Ok(png)
}

/// `println!` that returns an error instead of panicking when stdout cannot be written
/// (closed pipe, full disk): `outln!(...)?`.
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($arg)*)
            .map_err(|e| std::io::Error::new(e.kind(), format!("writing to stdout: {e}")))
    }};
}

/// Print a tool's one-line error to stderr (ignoring a failure to do so) and exit with `code`.
pub fn exit_with_error(tool: &str, error: &dyn std::fmt::Display, code: i32) -> ! {
    let _ = writeln!(std::io::stderr(), "{tool}: {error:#}");
    std::process::exit(code)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An output given as a symbolic link is refused as one (not as some other kind of file),
    /// and a path the system cannot even look up (a NUL in its name) is an error, not taken
    /// for a file that does not exist yet (both survived the third mutation sample).
    #[test]
    fn outputs_that_are_links_or_unreadable_paths_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (target, link) = (dir.path().join("real.hmb"), dir.path().join("link.hmb"));
        std::fs::write(&target, b"x").unwrap();
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let err = OutputPath::check(&link, &[]).unwrap_err().to_string();
        assert!(err.contains("symbolic link"), "{err}");
        assert!(OutputPath::check(Path::new("bad\0name.hmb"), &[]).is_err());
    }

    /// Outputs are refused by what they are, each naming why: a folder, a FIFO, a path below
    /// a file, a path with no file name. Two spellings of one place are one output; a device
    /// may be named twice (both written in place); an output in folders that do not exist yet
    /// makes them when written, and the first folder made is the outermost.
    #[cfg(target_os = "linux")]
    #[test]
    fn outputs_are_refused_by_kind_and_compared_by_place() {
        let dir = tempfile::tempdir().unwrap();
        let why = |p: &Path| OutputPath::check(p, &[]).unwrap_err().to_string();
        assert!(
            why(dir.path()).contains("is a folder"),
            "{}",
            why(dir.path())
        );
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.unwrap().success());
        assert!(why(&fifo).contains("FIFO"), "{}", why(&fifo));
        let file = dir.path().join("plain.txt");
        std::fs::write(&file, b"x").unwrap();
        let below = file.join("out.png");
        assert!(why(&below).contains("is not a folder"), "{}", why(&below));
        let bare = dir.path().join("new").join("..");
        assert!(why(&bare).contains("not a file path"), "{}", why(&bare));
        let mut files = RunFiles::new();
        files.output(&dir.path().join("a.png"), "--out").unwrap();
        let again = dir.path().join(".").join("a.png");
        let err = files.output(&again, "--also").unwrap_err().to_string();
        assert!(err.contains("also this run's output"), "{err}");
        files.output(Path::new("/dev/null"), "--x").unwrap();
        files.output(Path::new("/dev/null"), "--y").unwrap();
        let deep = dir.path().join("m").join("n").join("o.txt");
        let out = OutputPath::check(&deep, &[]).unwrap();
        assert_eq!(
            out.missing,
            vec![dir.path().join("m"), dir.path().join("m/n")]
        );
        out.write(b"o").unwrap();
        assert_eq!(std::fs::read(&deep).unwrap(), b"o");
        assert_eq!(out.path(), deep.as_path());
    }

    /// Every missing folder of a path is listed, outermost first, up to the first that exists
    /// (a survivor of the 2026-12-06 mutation sample stopped after the innermost one, so a
    /// failed run would have left the outer ones behind).
    #[test]
    fn missing_folders_lists_each_level_to_the_first_that_exists() {
        let root = tempfile::tempdir().unwrap();
        let deep = root.path().join("a").join("b").join("c");
        let missing = missing_folders(&deep, "--out").unwrap();
        let a = root.path().join("a");
        assert_eq!(missing, vec![a.clone(), a.join("b"), deep.clone()]);
        std::fs::create_dir_all(&deep).unwrap();
        assert!(missing_folders(&deep, "--out").unwrap().is_empty());
    }

    /// A relative path's levels stop at its first component: the empty path above it is not
    /// a folder to make (a guard that let it through listed "" first).
    #[test]
    fn missing_folders_of_a_relative_path_stop_at_its_first_component() {
        let top = PathBuf::from(format!("hairmesh-no-such-folder-{}", std::process::id()));
        let deep = top.join("sub");
        let missing = missing_folders(&deep, "--out").unwrap();
        assert_eq!(missing, vec![top.clone(), deep.clone()]);
    }

    /// A file that holds more than its metadata said (here a `/proc` file, which reports 0
    /// bytes) is still refused past the limit: the read takes one byte more than the limit to
    /// see it, where reading exactly the limit would have accepted it cut short.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_file_longer_than_its_metadata_is_refused_past_the_limit() {
        let status = Path::new("/proc/self/status");
        assert_eq!(std::fs::metadata(status).unwrap().len(), 0);
        let err = read_input(status, 64).unwrap_err().to_string();
        assert!(err.contains("64-byte limit"), "{err}");
        assert!(read_input(status, 1 << 20).unwrap().len() > 64);
    }

    /// The size limit is inclusive: a file of exactly `max_bytes` is read, one byte more is
    /// refused naming the limit, and a folder is refused before anything is read.
    #[test]
    fn inputs_are_read_up_to_their_limit_and_no_further() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("eight.bin");
        std::fs::write(&f, b"12345678").unwrap();
        assert_eq!(read_input(&f, 8).unwrap(), b"12345678");
        let err = read_input(&f, 7).unwrap_err().to_string();
        assert!(
            err.contains("eight.bin") && err.contains("7-byte limit"),
            "{err}"
        );
        let err = read_input(dir.path(), 1 << 20).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
        std::fs::write(&f, [0xff, 0xfe]).unwrap();
        assert!(
            read_text_input(&f, 8)
                .unwrap_err()
                .to_string()
                .contains("not UTF-8")
        );
    }

    /// An output that is one of the run's inputs is refused; another file in the same folder
    /// (same device, another inode) is not.
    #[test]
    fn an_output_may_not_overwrite_an_input() {
        let dir = tempfile::tempdir().unwrap();
        let (input, other) = (dir.path().join("in.obj"), dir.path().join("out.obj"));
        std::fs::write(&input, b"v 0 0 0").unwrap();
        std::fs::write(&other, b"old").unwrap();
        let err = OutputPath::check(&input, &[&input])
            .unwrap_err()
            .to_string();
        assert!(err.contains("refusing to overwrite"), "{err}");
        OutputPath::check(&other, &[&input]).unwrap();
        let mut files = RunFiles::new();
        files.input(&input);
        files.output(&other, "--out").unwrap();
        let err = files.output(&other, "--also").unwrap_err().to_string();
        assert!(err.contains("also this run's output"), "{err}");
    }

    /// Character devices are written in place, after the files: `/dev/null` is accepted as an
    /// output, and a write to `/dev/full` (always "no space left") fails the run.
    #[cfg(target_os = "linux")]
    #[test]
    fn devices_are_outputs_written_in_place() {
        let null = OutputPath::check(Path::new("/dev/null"), &[]).unwrap();
        assert_eq!(null.kind, OutputKind::Device);
        let full = OutputPath::check(Path::new("/dev/full"), &[]).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let file = OutputPath::check(&dir.path().join("a.txt"), &[]).unwrap();
        write_together(&[(&null, b"n"), (&file, b"a")]).unwrap();
        assert_eq!(std::fs::read(dir.path().join("a.txt")).unwrap(), b"a");
        let err = write_together(&[(&full, b"f")]).unwrap_err().to_string();
        assert!(err.contains("/dev/full"), "{err}");
    }

    /// A staged folder appears with every written file on publish, and not at all when the
    /// run is dropped before publishing.
    #[test]
    fn staged_folders_appear_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let names = ["a.png".to_string(), "b.csv".to_string()];
        let target = dir.path().join("frames");
        let mut staged =
            StagedFolder::check(&target, &names, &mut RunFiles::new(), "--out").unwrap();
        staged.write("a.png", b"A").unwrap();
        drop(staged);
        assert!(!target.exists());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "staging left behind"
        );
        let mut staged =
            StagedFolder::check(&target, &names, &mut RunFiles::new(), "--out").unwrap();
        staged.write("a.png", b"A").unwrap();
        staged.write("b.csv", b"B").unwrap();
        staged.publish().unwrap();
        assert_eq!(std::fs::read(target.join("a.png")).unwrap(), b"A");
        assert_eq!(std::fs::read(target.join("b.csv")).unwrap(), b"B");
        // Into an existing folder: the files move in, the staging folder goes.
        let mut staged =
            StagedFolder::check(&target, &names, &mut RunFiles::new(), "--out").unwrap();
        staged.write("b.csv", b"C").unwrap();
        staged.publish().unwrap();
        assert_eq!(std::fs::read(target.join("b.csv")).unwrap(), b"C");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn outputs_written_together_appear_all_or_none() {
        let dir = tempfile::tempdir().unwrap();
        let (a, sub) = (dir.path().join("a.obj"), dir.path().join("sub"));
        std::fs::create_dir(&sub).unwrap();
        let b = sub.join("b.toml");
        let (oa, ob) = (
            OutputPath::check(&a, &[]).unwrap(),
            OutputPath::check(&b, &[]).unwrap(),
        );
        // The second output's folder disappears before the write: the first is not written.
        std::fs::remove_dir(&sub).unwrap();
        let err = write_together(&[(&oa, b"1"), (&ob, b"2")]).unwrap_err();
        assert!(err.to_string().contains("b.toml"), "{err}");
        assert!(!a.exists());
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "temporary files left: {left:?}");
        std::fs::create_dir(&sub).unwrap();
        write_together(&[(&oa, b"1"), (&ob, b"2")]).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"1");
        assert_eq!(std::fs::read(&b).unwrap(), b"2");
    }
}
