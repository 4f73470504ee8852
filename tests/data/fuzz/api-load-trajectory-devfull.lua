-- fuzz case: dm.load_trajectory('/dev/full') read an endless line of NUL bytes (hang)
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.load_trajectory"](H["s_devfull"])
end
