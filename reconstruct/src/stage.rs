//! The step a running reconstruction is in, for a progress display: a
//! 1224×1024 capture takes 15–23 s under SMSfP, and a spinner alone does not
//! say whether it is segmenting or solving. A caller listens on its own
//! thread ([`listen`]); a method announces each step there ([`enter`]).
//! Nothing listens in sweeps, where many runs share the threads.

use std::cell::RefCell;

type Listener = Box<dyn Fn(&str)>;

thread_local! {
    static LISTENER: RefCell<Option<Listener>> = const { RefCell::new(None) };
}

/// Tells this thread's listener, if any, that `stage` begins.
pub fn enter(stage: &str) {
    LISTENER.with(|l| {
        if let Some(listener) = l.borrow().as_ref() {
            listener(stage);
        }
    });
}

/// Runs `run` with `listener` hearing every [`enter`] made on this thread.
pub fn listen<R>(listener: impl Fn(&str) + 'static, run: impl FnOnce() -> R) -> R {
    struct Restore(Option<Listener>);
    impl Drop for Restore {
        fn drop(&mut self) {
            LISTENER.with(|l| *l.borrow_mut() = self.0.take());
        }
    }
    let previous = LISTENER.with(|l| l.borrow_mut().replace(Box::new(listener)));
    let _restore = Restore(previous);
    run()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::rc::Rc;

    #[test]
    fn a_listener_hears_the_stages_of_its_run_only() {
        let heard = Rc::new(RefCell::new(Vec::new()));
        enter("before");
        let h = heard.clone();
        let out = listen(
            move |s| h.borrow_mut().push(s.to_string()),
            || {
                enter("one");
                std::thread::spawn(|| enter("elsewhere")).join().unwrap();
                enter("two");
                7
            },
        );
        enter("after");
        assert_eq!(out, 7);
        assert_eq!(*heard.borrow(), ["one", "two"]);
    }
}
