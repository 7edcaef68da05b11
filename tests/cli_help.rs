//! Every command's `--help` gives an example, and its own options before
//! the global ones (issue 25: a user reads the top of the help first).

mod common;
use common::campanile;

/// The subcommands a `--help` text lists under "Commands:" (not `help`).
fn subcommands(help: &str) -> Vec<String> {
    let Some(start) = help.find("\nCommands:\n") else {
        return vec![];
    };
    help[start + 11..]
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .filter(|l| l.starts_with("  ") && !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}

#[test]
fn every_command_has_an_example_and_its_own_options_first() {
    let top = String::from_utf8(campanile(&["--help"]).stdout).unwrap();
    let mut queue: Vec<Vec<String>> = subcommands(&top).into_iter().map(|c| vec![c]).collect();
    assert!(queue.len() >= 14, "{top}");
    let mut leaves = 0;
    let mut failures = Vec::new();
    while let Some(path) = queue.pop() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let out = campanile(&args);
        assert!(out.status.success(), "campanile {}", args.join(" "));
        let help = String::from_utf8(out.stdout).unwrap();
        let subs = subcommands(&help);
        // A command with subcommands and no action of its own (`hdr`) lists
        // them; each of those is a leaf to check. `devices` is both.
        let runs_itself = subs.is_empty() || path == ["devices"];
        for s in subs {
            let mut p = path.clone();
            p.push(s);
            queue.push(p);
        }
        if !runs_itself {
            continue;
        }
        leaves += 1;
        let name = path.join(" ");
        if !help.contains("Example") {
            failures.push(format!("`campanile {name} --help` has no example"));
        }
        if !help.contains(&format!("campanile {name}")) {
            failures.push(format!(
                "`campanile {name} --help`: its example does not run `campanile {name}`"
            ));
        }
        match (help.find("\nOptions:\n"), help.find("\nGlobal options:\n")) {
            (Some(own), Some(global)) if own < global => {}
            (None, Some(_)) => {}
            _ => failures.push(format!(
                "`campanile {name} --help`: its own options do not come before the global ones"
            )),
        }
    }
    assert!(leaves >= 24, "{leaves} commands checked");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
