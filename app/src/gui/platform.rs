//! Where the workbench runs, as the workbench sees it: the few things a browser page gives that a
//! desktop window does not. The GUI calls this interface; the page (`web.rs`) implements it
//! and starts the GUI, so the GUI never imports the page.

use super::report::Report;

/// What the workbench asks of the place it runs in.
pub trait Platform {
    /// Writes a line where a developer looks (the browser console); nowhere on the desktop.
    fn log(&self, _line: &str) {}

    /// The fragment (`#…`) of the address the workbench was opened at, a link to a state
    /// ([`super::link`]); empty where there is none.
    fn fragment(&self) -> String {
        String::new()
    }

    /// The address a link to a state starts with: the page's own in a browser, the published
    /// page ([`super::link::page_url`]) on the desktop.
    fn page_address(&self) -> String {
        super::link::page_url()
    }

    /// Whether [`Platform::publish`] wants the state after every frame (a page under test does).
    fn publishes(&self) -> bool {
        false
    }

    /// Keeps the workbench's state after a frame, for whoever reads it (a browser test).
    fn publish(&self, _report: &Report) {}
}

/// The desktop window: nothing beyond the defaults.
pub struct Desktop;

impl Platform for Desktop {}
