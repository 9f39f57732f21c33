//! Families read from constraint files ([`crate::constraint_file`]), joined to the table at run
//! time: each gets a row after the built-in ones, so that everything that reads the table (the
//! command line, both solvers, the stepper, the inspector, what is drawn and recorded, lessons)
//! handles it like any other family. Its [`Constraint`] type evaluates the file's compiled tape.
//!
//! A family keeps its place (its [`Family`] number) for the life of the process. Loading a file
//! of the same name again ([`Family::define`]: the workbench's editor, a file opened twice)
//! redefines it in that place; simulations notice ([`Family::generation`]) and rebuild its
//! constraints.

use super::Family;
use super::table::{Kind, MAX_FAMILIES, Row, TABLE};
use crate::constraint_file::ConstraintFile;
use std::collections::HashSet;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, RwLock};

/// The colours of file families' arrows, in the order they are loaded (then again): teal, rose,
/// lime and slate, apart from the built-in families' (orange, green, blue, brown, purple), the
/// red of inverted tets, the yellow of the selection, the magenta of corrections and the cyan of
/// step-by-step mode.
pub const COLOURS: [[u8; 4]; 4] = [
    [0, 150, 150, 255],
    [235, 100, 160, 255],
    [140, 170, 30, 255],
    [110, 110, 140, 255],
];

/// How many families files can add to the table.
pub const MAX_FILE_FAMILIES: usize = MAX_FAMILIES - TABLE.len();

/// One registered family: its row, its file, and how often it was defined.
struct Registered {
    row: &'static Row,
    file: Arc<ConstraintFile>,
    generation: u64,
}

static REGISTERED: RwLock<Vec<Registered>> = RwLock::new(Vec::new());
/// How many families are registered (read without the lock: [`Family::all`]).
static COUNT: AtomicUsize = AtomicUsize::new(0);
/// Grows with every definition: a simulation that saw another value looks again.
static GENERATION: AtomicU64 = AtomicU64::new(1);

/// How many families the table has now: the built-in ones and those from files.
pub(super) fn count() -> usize {
    TABLE.len() + COUNT.load(Ordering::Acquire)
}

/// The value of the definition counter: it changes whenever a family is (re)defined.
pub fn definitions() -> u64 {
    GENERATION.load(Ordering::Acquire)
}

fn registered() -> std::sync::RwLockReadGuard<'static, Vec<Registered>> {
    REGISTERED.read().unwrap_or_else(|e| e.into_inner())
}

/// The row of file family `index` (counted after the built-in ones).
pub(super) fn row(index: usize) -> &'static Row {
    registered()[index].row
}

/// The file of family `index` (counted after the built-in ones).
pub(super) fn file(index: usize) -> Arc<ConstraintFile> {
    Arc::clone(&registered()[index].file)
}

/// How often family `index` (counted after the built-in ones) has been defined.
pub(super) fn generation(index: usize) -> u64 {
    registered()[index].generation
}

/// A string that lives as long as the process, stored once however often it is asked for.
fn intern(text: &str) -> &'static str {
    static STRINGS: Mutex<Option<HashSet<&'static str>>> = Mutex::new(None);
    let mut strings = STRINGS.lock().unwrap_or_else(|e| e.into_inner());
    let strings = strings.get_or_insert_with(HashSet::new);
    if let Some(&known) = strings.get(text) {
        return known;
    }
    let leaked: &'static str = Box::leak(text.to_owned().into_boxed_str());
    strings.insert(leaked);
    leaked
}

/// The row a file's family gets in place `slot` (counted after the built-in ones).
fn row_of(file: &ConstraintFile, slot: usize) -> &'static Row {
    let name = intern(&file.name);
    let formula: Vec<&'static str> = file.formula.iter().map(|l| intern(l)).collect();
    Box::leak(Box::new(Row {
        name,
        aliases: &[],
        title: intern(&format!("{} ({})", file.name, file.path.display())),
        label: name,
        colour: COLOURS[slot % COLOURS.len()],
        formula: Box::leak(formula.into_boxed_slice()),
        rest_symbol: "rest",
        arity: file.arity(),
        binding: file.binding,
        needs_face_p0_p2_p3: false,
        group: name,
        compliance_from_material: None,
        projected_with: None,
        kind: Kind::File,
    }))
}

/// Why a file's family cannot join the table under its name, if a built-in family or group
/// already has it.
fn clashes_with_builtin(name: &str) -> Option<String> {
    let builtin = TABLE
        .iter()
        .any(|row| row.name == name || row.aliases.contains(&name) || row.group == name);
    builtin.then(|| {
        format!("name \"{name}\" is a built-in constraint family's: give the file another name")
    })
}

impl Family {
    /// Adds the family of a constraint file to the table: its place, or the place it already
    /// has when the same file (same path and text) was registered before. An error when another
    /// family has its name (a built-in one, or another file's: two files may not share a name)
    /// or the table is full.
    ///
    /// ```
    /// use std::path::Path;
    /// use tetlab_core::constraint_file::ConstraintFile;
    /// use tetlab_core::constraints::{Family, PerFamily};
    /// let text = "name = \"doc-edge\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1) - rest\"\n";
    /// let file = ConstraintFile::parse(Path::new("doc-edge.toml"), text).unwrap();
    /// let family = Family::register(file.clone()).unwrap();
    /// assert_eq!(Family::register(file).unwrap(), family, "the same file, the same family");
    /// // It is a family like the others: by name on the command line, in lists, in the table.
    /// assert_eq!(Family::parse("doc-edge"), Ok(family));
    /// assert!(PerFamily::parse_list("volume,doc-edge").unwrap()[family]);
    /// assert_eq!((family.arity(), family.row().label), (2, "doc-edge"));
    /// ```
    pub fn register(file: ConstraintFile) -> Result<Family, String> {
        Family::add(file, false)
    }

    /// [`Family::register`], except that a file of a name already registered (from another
    /// path or with another text) redefines that family in its place: the workbench's editor,
    /// or a file edited and opened again. Simulations that use it rebuild its constraints
    /// ([`crate::simulation::Simulation::refresh_families`]).
    pub fn define(file: ConstraintFile) -> Result<Family, String> {
        Family::add(file, true)
    }

    fn add(file: ConstraintFile, redefine: bool) -> Result<Family, String> {
        if let Some(why) = clashes_with_builtin(&file.name) {
            return Err(why);
        }
        let mut registered = REGISTERED.write().unwrap_or_else(|e| e.into_inner());
        if let Some(slot) = registered.iter().position(|r| r.row.name == file.name) {
            let family = Family::from_index(TABLE.len() + slot);
            let same = {
                let known = &registered[slot].file;
                known.path == file.path && known.source == file.source
            };
            if same {
                return Ok(family);
            }
            if !redefine {
                return Err(format!(
                    "name \"{}\" is already the name of {}: give this file another name",
                    file.name,
                    registered[slot].file.path.display()
                ));
            }
            let generation = GENERATION.fetch_add(1, Ordering::AcqRel) + 1;
            registered[slot] = Registered {
                row: row_of(&file, slot),
                file: Arc::new(file),
                generation,
            };
            return Ok(family);
        }
        let slot = registered.len();
        if slot >= MAX_FILE_FAMILIES {
            return Err(format!(
                "at most {MAX_FILE_FAMILIES} constraint files can be loaded at once"
            ));
        }
        let generation = GENERATION.fetch_add(1, Ordering::AcqRel) + 1;
        registered.push(Registered {
            row: row_of(&file, slot),
            file: Arc::new(file),
            generation,
        });
        COUNT.store(registered.len(), Ordering::Release);
        Ok(Family::from_index(TABLE.len() + slot))
    }
}
